"""Trace-based time-response metrics: the independent oracle for the loop's streaming metrics."""

from __future__ import annotations

import numpy as np


def rise_time(t: np.ndarray, y: np.ndarray, start: float, target: float) -> np.ndarray:
    """10–90 % rise time [s] of each row of y from `start` to `target`; NaN if never reached."""
    y = np.atleast_2d(y)
    span = target - start
    frac = (y - start) / span if span != 0 else np.full(y.shape, np.nan)
    t10 = _first_time(t, frac >= 0.1)
    t90 = _first_time(t, frac >= 0.9)
    return t90 - t10


def sinusoid_fit(t: np.ndarray, y: np.ndarray, frequency: float) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares amplitude and phase [rad] of y ≈ c + A·sin(ω t + φ) for each row of y."""
    X = np.column_stack([np.ones_like(t), np.sin(frequency * t), np.cos(frequency * t)])
    coef, *_ = np.linalg.lstsq(X, np.atleast_2d(y).T, rcond=None)
    a_sin, a_cos = coef[1], coef[2]
    return np.hypot(a_sin, a_cos), np.arctan2(a_cos, a_sin)


def _first_time(t: np.ndarray, hit: np.ndarray) -> np.ndarray:
    """Time of the first True in each row; NaN where a row has none."""
    idx = hit.argmax(axis=1)
    return np.where(hit.any(axis=1), t[idx], np.nan)
