"""Fitting a model's constants to a recording: scipy's least_squares on their logarithms (so
every constant stays positive and the step is relative), standard errors from the Jacobian,
and the constants the data do not determine named as such."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

UNDETERMINED = 0.25  # relative standard error above which a constant counts as not determined
SPREAD = 10.0  # the fit keeps each constant within this factor of where it starts


@dataclass(frozen=True)
class Fit:
    """Constants fitted to data.

    Attributes:
        values: name -> fitted value (SI), the determined ones only.
        standard_errors: name -> its standard error (SI), the determined ones only.
        unidentifiable: the constants the data do not determine (relative standard error
            above UNDETERMINED, no effect on the residuals at all, or driven to a factor
            SPREAD from the start), never given a value.
        cost: half the sum of the squared weighted residuals at the fit.
        residual_sigma: the residuals' standard deviation (weighted units), the noise the
            standard errors assume.
    """

    values: dict[str, float]
    standard_errors: dict[str, float]
    unidentifiable: tuple[str, ...]
    cost: float
    residual_sigma: float


def fit_constants(
    residuals: Callable[[dict[str, float]], np.ndarray],
    start: dict[str, float],
    free: Sequence[str],
) -> Fit:
    """Fit the `free` constants so that residuals(constants) is least in the squares.

    Args:
        residuals: constants (name -> value, SI) -> the weighted residuals, shape (m,).
        start: every constant's value to start from (the fixed ones keep theirs), SI, > 0;
            the fit keeps each within a factor SPREAD of it.
        free: the names of the constants to fit.

    Returns:
        The fit (its standard errors from the Jacobian at the optimum: residuals taken as
        independent, so they are a lower bound where the residuals are correlated).
    """
    names = list(free)

    def weighted(log_values: np.ndarray) -> np.ndarray:
        """The residuals at exp(log_values)."""
        return residuals(start | dict(zip(names, np.exp(log_values), strict=True)))

    x0 = np.log([start[name] for name in names])
    bounds = (x0 - np.log(SPREAD), x0 + np.log(SPREAD))
    solution = least_squares(
        weighted, x0, bounds=bounds, x_scale="jac", method="trf", xtol=1e-12, ftol=1e-12
    )
    at_bound = np.isclose(solution.x, bounds[0], atol=1e-6) | np.isclose(
        solution.x, bounds[1], atol=1e-6
    )
    m, p = solution.fun.size, len(names)
    sigma2 = 2.0 * solution.cost / max(m - p, 1)
    jac = solution.jac
    # Relative standard errors = standard errors of the logarithms: sqrt(diag(σ² (JᵀJ)⁻¹)).
    _, s, vt = np.linalg.svd(jac, full_matrices=False)
    tiny = s <= s.max() * 1e-10 if s.size else s.astype(bool)
    inverse = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, s) ** 2)
    relative = np.sqrt(sigma2 * np.einsum("ki,k,ki->i", vt, inverse, vt))
    # A direction of (almost) no effect leaves its constants undetermined, whatever else says.
    loose = np.any(np.abs(vt[tiny]) > 1e-3, axis=0) if tiny.any() else np.zeros(p, dtype=bool)
    values, errors, unknown = {}, {}, []
    for k, name in enumerate(names):
        if loose[k] or at_bound[k] or not relative[k] <= UNDETERMINED:
            unknown.append(name)
            continue
        values[name] = float(np.exp(solution.x[k]))
        errors[name] = float(values[name] * relative[k])
    return Fit(values, errors, tuple(unknown), float(solution.cost), float(np.sqrt(sigma2)))


def nrmse(measured: np.ndarray, model: np.ndarray) -> float:
    """The model's RMS error over the measured signal's standard deviation (0: exact, 1: no
    better than its mean).

    Args:
        measured: the measured signal, shape (n,).
        model: the model's, shape (n,).

    Returns:
        The normalised RMS error.
    """
    spread = float(np.std(measured))
    error = float(np.sqrt(np.mean((model - measured) ** 2)))
    return error / spread if spread > 0 else (0.0 if error == 0 else np.inf)
