"""Joint limits a URDF does not state: acceleration and jerk, each from a rise time.

A URDF gives each joint a speed limit (and an effort limit), but no acceleration or jerk limit.
Without stated ones, a joint may reach its speed limit from rest in no less than ACCEL_TIME,
and its acceleration limit from zero in no less than JERK_TIME.
"""

from __future__ import annotations

import numpy as np

from articula.errors import ConfigError

__all__ = ["ACCEL_TIME", "JERK_TIME", "rise_limit"]

# [s] A Franka's 7.5-20 rad/s² reach its speed limits in 0.1-0.3 s.
ACCEL_TIME = 0.25
# [s] One 10 ms control period (a Franka's is 2 ms: 7500 rad/s³ at 15 rad/s²).
JERK_TIME = 0.01


def rise_limit(limits: np.ndarray, rise_time: float, key: str = "accel_time") -> np.ndarray:
    """The limit of the next derivative that reaches each limit from zero in `rise_time`:
    limit / rise_time (speed → acceleration, acceleration → jerk); inf where a joint has no
    limit (0 or inf).

    Args:
        limits: joint limits, shape (nq,) (e.g. speeds [rad/s or m/s]).
        rise_time: time from zero to the limit [s], > 0.
        key: the setting `rise_time` came from, named in the error.

    Returns:
        The limits of the next derivative, shape (nq,) (e.g. accelerations [rad/s²]).
    """
    if not (np.isfinite(rise_time) and rise_time > 0):
        raise ConfigError(key, f"must be finite and > 0 s (got {rise_time})")
    limits = np.asarray(limits, dtype=float)
    with np.errstate(over="ignore"):  # a limit near the float range has no useful one above
        return np.where(limits > 0, limits / rise_time, np.inf)
