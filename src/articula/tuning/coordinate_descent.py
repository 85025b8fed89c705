"""Coordinate descent exactly as Algorithm 1 of chapter 2, for any cost of a parameter vector."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from articula.errors import ConfigError

Cost = Callable[[np.ndarray], float]


@dataclass(frozen=True)
class DescentStep:
    """The state after one sweep over all coordinates (one `count` of Algorithm 1)."""

    count: int
    k: np.ndarray
    dk: np.ndarray
    best_cost: float
    evaluations: int


@dataclass(frozen=True)
class DescentResult:
    """Optimised parameters K*, their cost M(K*), and the history of every sweep."""

    k: np.ndarray
    cost: float
    evaluations: int
    history: list[DescentStep] = field(default_factory=list)


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
    """
    k = np.array(k0, dtype=float)
    dk = np.array(dk0, dtype=float)
    if k.ndim != 1 or dk.shape != k.shape:
        raise ConfigError("dk0", f"must have the shape of k0 {k.shape} (got {dk.shape})")
    if not (np.all(np.isfinite(k)) and np.all(np.isfinite(dk)) and np.all(dk > 0)):
        raise ConfigError("dk0", "k0 must be finite and dk0 finite and positive")
    lo = np.full(k.shape, -np.inf) if lower is None else np.asarray(lower, dtype=float)
    hi = np.full(k.shape, np.inf) if upper is None else np.asarray(upper, dtype=float)
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
