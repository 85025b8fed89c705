"""Coordinate descent exactly as Algorithm 1 of chapter 2, for any cost of a parameter vector."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from articula.errors import ConfigError
from articula.tuning.response import readonly

Cost = Callable[[np.ndarray], float]


@dataclass(frozen=True, eq=False)
class DescentStep:
    """The state after one sweep over all coordinates (one `count` of Algorithm 1).

    k and dk are stored as read-only copies.

    Attributes:
        count: number of sweeps done (0 = the random start).
        k: parameters K after this sweep, shape (p,).
        dk: probing steps dK after this sweep, shape (p,).
        best_cost: lowest cost M found so far.
        evaluations: number of cost evaluations so far.
    """

    count: int
    k: np.ndarray
    dk: np.ndarray
    best_cost: float
    evaluations: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "k", readonly(self.k))
        object.__setattr__(self, "dk", readonly(self.dk))


@dataclass(frozen=True, eq=False)
class DescentResult:
    """Optimised parameters K* (read-only copy), their cost M(K*), and every sweep's state.

    Attributes:
        k: optimised parameters K*, shape (p,).
        cost: their cost M(K*).
        evaluations: number of cost evaluations made (probes outside the bounds not counted).
        history: the state after each sweep; history[0] holds the random start, so
            history[0].k against k shows what moved.
    """

    k: np.ndarray
    cost: float
    evaluations: int
    history: list[DescentStep] = field(default_factory=list)

    def __post_init__(self) -> None:
        object.__setattr__(self, "k", readonly(self.k))


def coordinate_descent(
    cost: Cost,
    k0: np.ndarray,
    dk0: np.ndarray,
    k_stop: float,
    max_iterations: int,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
) -> DescentResult:
    """Minimise `cost` from K = k0 with probing steps dK = dk0 (chapter 2, Algorithm 1).

    Each coordinate is probed at K[i] + dK[i], then at K[i] - dK[i]; a probe that does not
    raise the best cost is kept and grows its step by 1.2, otherwise K[i] is restored and the
    step shrinks by 0.8. It stops when |dK|_1 < k_stop or after `max_iterations` sweeps.
    `lower`/`upper` (optional) are bounds the book does not have: a probe outside them counts
    as a failure without being evaluated, so that, e.g., a gain never turns negative. The
    random K and dK of the algorithm's first lines are the caller's (draw them from a seeded
    Generator), so a tuning run is reproducible.

    Args:
        cost: cost M(K) of a parameter vector, e.g. one experiment's Eq. (2.5); lower is better.
        k0: starting parameters K, shape (p,).
        dk0: starting probing steps dK, positive, shape (p,).
        k_stop: threshold on |dK|_1 below which the search stops.
        max_iterations: most sweeps over all coordinates.
        lower: lower bounds on K, shape (p,); None for none.
        upper: upper bounds on K, shape (p,); None for none.

    Returns:
        The optimised parameters, their cost and the state after every sweep.
    """
    k = np.array(k0, dtype=float)
    dk = np.array(dk0, dtype=float)
    if k.ndim != 1 or k.size == 0 or not np.all(np.isfinite(k)):
        raise ConfigError("k0", f"must be a finite non-empty 1-D vector (got {k.tolist()})")
    if dk.shape != k.shape:
        raise ConfigError("dk0", f"must have the shape of k0 {k.shape} (got {dk.shape})")
    if not (np.all(np.isfinite(dk)) and np.all(dk > 0)):
        raise ConfigError("dk0", f"must be finite and positive (got {dk.tolist()})")
    if isinstance(k_stop, bool) or not (np.isfinite(k_stop) and k_stop >= 0):
        raise ConfigError("k_stop", f"must be finite and >= 0 (got {k_stop!r})")
    if (
        isinstance(max_iterations, bool)
        or not isinstance(max_iterations, int | np.integer)
        or max_iterations < 1
    ):
        raise ConfigError("max_iterations", f"must be an integer >= 1 (got {max_iterations!r})")
    lo = np.full(k.shape, -np.inf) if lower is None else np.array(lower, dtype=float)
    hi = np.full(k.shape, np.inf) if upper is None else np.array(upper, dtype=float)
    for name, bound in (("lower", lo), ("upper", hi)):
        if bound.shape != k.shape or np.any(np.isnan(bound)):
            raise ConfigError(
                name, f"must be a vector of the shape of k0 {k.shape}, no NaN (got {bound.shape})"
            )
    if np.any(lo > hi):
        raise ConfigError("upper", f"must be >= lower (got {hi.tolist()} < {lo.tolist()})")
    if np.any(k < lo) or np.any(k > hi):
        raise ConfigError("k0", f"must lie within the bounds (got {k.tolist()})")
    evaluations = 1
    best = float(cost(k.copy()))
    history = [DescentStep(0, k.copy(), dk.copy(), best, evaluations)]

    def probe(trial: np.ndarray) -> float:
        nonlocal evaluations
        if np.any(trial < lo) or np.any(trial > hi):
            return np.inf
        evaluations += 1
        return float(cost(trial.copy()))

    count = 0
    while np.sum(np.abs(dk)) >= k_stop and count < max_iterations:
        for i in range(k.size):
            for sign in (1.0, -1.0):
                trial = k.copy()
                trial[i] += sign * dk[i]
                value = probe(trial)
                if value <= best:  # "error <= best_error" of Algorithm 1
                    k, best = trial, value
                    dk[i] *= 1.2
                    break
            else:
                dk[i] *= 0.8
        count += 1
        history.append(DescentStep(count, k.copy(), dk.copy(), best, evaluations))
    return DescentResult(k, best, evaluations, history)
