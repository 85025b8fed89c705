"""Bring a commanded joint motion to rest: every joint decelerates at its limit, tick by tick
(what a controller's stopj does)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

__all__ = ["brake_step", "braking_ticks"]


def brake_step(
    q: np.ndarray, qd: np.ndarray, deceleration: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray]:
    """One tick of braking.

    Args:
        q: the joints where the motion is, shape (n,) [rad].
        qd: their velocities, shape (n,) [rad/s].
        deceleration: each joint's deceleration, shape (n,) [rad/s²] (> 0).
        h: the tick [s].

    Returns:
        The joints [rad] and velocities [rad/s] a tick later.
    """
    step = np.asarray(deceleration, dtype=float) * h
    qd = qd - np.clip(qd, -step, step)
    return q + qd * h, qd


def braking_ticks(
    q: np.ndarray, qd: np.ndarray, deceleration: np.ndarray, h: float
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """The commanded positions and velocities that bring a motion to rest.

    Args:
        q: the joints where the motion is, shape (n,) [rad].
        qd: their velocities, shape (n,) [rad/s].
        deceleration: each joint's deceleration, shape (n,) [rad/s²] (> 0).
        h: the tick [s].

    Yields:
        (q, qd) at each tick until every joint is at rest; the last has qd = 0.
    """
    q, qd = np.array(q, dtype=float), np.array(qd, dtype=float)
    while np.any(qd):
        q, qd = brake_step(q, qd, deceleration, h)
        yield q.copy(), qd.copy()
