"""Fitting a model's constants to a recording: scipy's least_squares on their logarithms (so
every constant stays positive and the step is relative), standard errors from the Jacobian,
and the constants the data do not determine named as such."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from articula.errors import ConfigError

UNDETERMINED = 0.25  # relative standard error above which a constant counts as not determined
SPREAD = 10.0  # the fit keeps each constant within this factor of where it starts
VALIDATION = 0.25  # the last quarter of each recording is kept for validation

# A model's prediction: (constants, recording index) -> channel name -> values, shape (n,).
Predict = Callable[[dict[str, float], int], dict[str, np.ndarray]]


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


@dataclass(frozen=True)
class Curve:
    """One channel of the first recording, measured and predicted, for the fit's figure.

    Attributes:
        label: the axis label (channel and unit).
        t: sample times [s], shape (n,).
        measured: the measured values, shape (n,).
        model: the fitted model's, shape (n,).
        validation_from: where the held-out part starts [s].
    """

    label: str
    t: np.ndarray
    measured: np.ndarray
    model: np.ndarray
    validation_from: float


@dataclass(frozen=True)
class Identification:
    """A fit and how well it predicts the data it was not fitted to.

    Attributes:
        fit: the fitted constants, their standard errors, the undetermined ones.
        validation_nrmse: channel -> NRMSE on the held-out part of every recording.
        start: every constant the model takes, as the fit started (SI).
        plant: the fitted plant as a config's tables (undetermined constants at their start).
        curves: the first recording's channels, measured against the model.
        bounds: constant -> what the recordings bound it by, for one the sampling cannot
            resolve (listed as unidentifiable too), e.g. "≥ 47.1 rad/s: ...".
    """

    fit: Fit
    validation_nrmse: dict[str, float]
    start: dict[str, float]
    plant: dict[str, Any]
    curves: tuple[Curve, ...]
    bounds: dict[str, str] = field(default_factory=dict)

    @property
    def constants(self) -> dict[str, float]:
        """Every constant: the fitted ones, the rest at their start (SI)."""
        return self.start | self.fit.values


def fit_recordings(
    predict: Predict,
    measured: Sequence[Mapping[str, np.ndarray]],
    start: dict[str, float],
    free: Sequence[str],
    first: Sequence[str] = (),
    hold_out_last: bool = False,
) -> tuple[Fit, dict[str, float], dict[str, float]]:
    """Fit `free` to the first three quarters of each recording, each channel's residuals
    weighted by its noise over all of them; the NRMSE of each channel on the rest.

    Transients that settle within a recording (a six-chamber actuation) leave nothing but
    noise in its last quarter: with `hold_out_last`, the last recording is held out whole and
    the others are fitted whole.

    Args:
        predict: (constants, recording index) -> channel -> the model's values.
        measured: each recording's channels (the ones compared), name -> values, shape (n,).
        start: every constant's start, SI, > 0.
        free: the constants to fit.
        first: constants fitted alone first, from the others' starts (ones a start estimate
            leaves far off).
        hold_out_last: validate on the last recording, whole (needs two or more).

    Returns:
        The fit, channel -> validation NRMSE, and every constant where the full fit started
        (after the `first` ones' own fit).
    """
    sizes = [len(next(iter(m.values()))) for m in measured]
    if hold_out_last:
        if len(measured) < 2:
            raise ConfigError("RECORDING", "give two or more recordings: the last validates")
        cuts = [*sizes[:-1], 0]
    else:
        cuts = [int(size * (1 - VALIDATION)) for size in sizes]
    channels = list(measured[0])
    # One recording that hardly moves a channel shows no noise on it: taken over all of them.
    fitted = [(m, cut) for m, cut in zip(measured, cuts, strict=True) if cut > 0]
    scale = {c: _noise([m[c][:cut] for m, cut in fitted]) for c in channels}

    def residuals(constants: dict[str, float]) -> np.ndarray:
        """The weighted residuals on every recording's fitted part."""
        parts = []
        for k, (m, cut) in enumerate(zip(measured, cuts, strict=True)):
            if cut > 0:  # a recording held out whole is not simulated
                model = predict(constants, k)
                parts += [(model[c] - m[c])[:cut] / scale[c] for c in channels]
        return np.concatenate(parts)

    begin = dict(start)
    if first:
        begin |= fit_constants(residuals, begin, first).values
    fit = fit_constants(residuals, begin, free)
    constants = begin | fit.values
    held: dict[str, tuple[list, list]] = {c: ([], []) for c in channels}
    for k, (m, cut) in enumerate(zip(measured, cuts, strict=True)):
        if cut == sizes[k]:
            continue  # fitted whole: nothing of it held out
        model = predict(constants, k)
        for c in channels:
            held[c][0].append(m[c][cut:])
            held[c][1].append(model[c][cut:])
    validation = {c: nrmse(np.concatenate(a), np.concatenate(b)) for c, (a, b) in held.items()}
    return fit, validation, begin


def _noise(signals: Sequence[np.ndarray]) -> float:
    """The signals' noise level: the spread of their second differences (/√6, white noise's)."""
    second = np.concatenate([np.diff(signal, 2) for signal in signals])
    level = float(np.std(second) / np.sqrt(6.0))
    spread = float(np.std(np.concatenate(signals)))
    return level if level > 0 else max(spread, 1e-12)


def sample_period(
    columns: Mapping[str, np.ndarray], needed: Sequence[str], at_least: int, where: str, what: str
) -> float:
    """A recording's sample period, once it is checked to have the `needed` columns, finite, at
    least `at_least` samples and evenly spaced times (a lossy line leaves gaps).

    Args:
        columns: the recording's trace columns, name -> values (t [s] among them).
        needed: the columns the fit takes besides t.
        at_least: the fewest samples a fit takes.
        where: the recording, named in errors.
        what: the kind of recording, for the message ("motor", "PneuNet").

    Returns:
        The sample period [s].
    """
    missing = [c for c in ("t", *needed) if c not in columns]
    if missing:
        raise ConfigError(where, f"not a {what} recording: no {', '.join(missing)} column")
    for name in ("t", *needed):
        if not np.all(np.isfinite(np.asarray(columns[name], dtype=float))):
            raise ConfigError(where, f"{name} has NaN or infinite samples: record again")
    t = np.asarray(columns["t"], dtype=float)
    if t.size < at_least:
        raise ConfigError(where, f"{t.size} samples: a fit needs at least {at_least}")
    steps = np.diff(t)
    dt = float(np.median(steps))
    if not (dt > 0 and np.allclose(steps, dt, rtol=1e-3, atol=1e-9)):
        raise ConfigError(where, "samples are not evenly spaced (a lossy line?): record again")
    return dt
