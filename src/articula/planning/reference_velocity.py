"""The end-effector velocity a resolved-rate controller commands over one control period."""

from __future__ import annotations

import numpy as np

from articula.validation import NonNegative, Positive, StrictModel


class RateParams(StrictModel):
    """What every resolved-rate baseline takes.

    Attributes:
        gain: K on the position error [1/s].
        influence: the distance below which an obstacle counts [m].
        speed_scale: fraction of the URDF joint velocity limits [-].
    """

    gain: NonNegative = 20.0
    influence: Positive = 0.15
    speed_scale: Positive = 1.0


def reference_velocity(
    x_ref: np.ndarray, previous_ref: np.ndarray | None, x: np.ndarray, dt: float, gain: float
) -> np.ndarray:
    """ẋ_r + K e [m/s] for the period that ends at the reference point x_ref [m].

    The feed-forward is the reference's motion over the period, (x_ref − previous_ref)/dt,
    and the feedback K [1/s] acts on the error against previous_ref, where the arm at x was
    meant to be: measuring it against x_ref as well would count the period's motion twice and
    leave a steady lag of one period's travel. Without a previous point: K (x_ref − x).
    """
    if previous_ref is None:
        return gain * (x_ref - x)
    return (x_ref - previous_ref) / dt + gain * (previous_ref - x)
