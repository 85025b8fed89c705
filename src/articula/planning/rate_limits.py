"""Joint speed and acceleration limits as a box the next configuration must stay in."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from articula.errors import ConfigError
from articula.numba_cache import jit

# The box is narrowed by this relative amount, so that round-off in q_{k+1} = q_k + motion
# cannot put a finite difference of the commanded positions a hair above a limit.
ROUND_OFF = 1e-9


@dataclass
class RateLimits:
    """Per-period bounds on joint motion, relative to the motion of the period before.

    With acceleration limits a joint also brakes in time for its position limits: its motion
    m toward a limit keeps m + m²/(2 a dt²) within the room left, the distance it needs to
    stop at its largest deceleration, so the next box is never empty.

    Attributes:
        velocity: the largest joint speeds [rad/s or m/s], one per joint (inf: none).
        dt: the control period [s].
        acceleration: the largest joint accelerations [rad/s² or m/s²], one per joint (inf:
            none); None: no acceleration limit.
        strained: whether the last box could not keep every limit (the motion before broke
            one: a measured motion, or limits changed during the run); it then keeps the
            position and speed limits and comes as close to the acceleration limit as it can.
    """

    velocity: np.ndarray
    dt: float
    acceleration: np.ndarray | None = None
    strained: bool = field(default=False, init=False)
    _last_motion: np.ndarray | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self.velocity = np.asarray(self.velocity, dtype=float)
        if not (np.all(self.velocity > 0) and np.isfinite(self.dt) and self.dt > 0):
            raise ConfigError("RateLimits.velocity", "speeds and dt must be > 0")
        if self.acceleration is not None:
            self.acceleration = np.broadcast_to(
                np.asarray(self.acceleration, dtype=float), self.velocity.shape
            ).copy()
            if not np.all(self.acceleration > 0):
                raise ConfigError(
                    "RateLimits.acceleration", f"must be > 0 (got {self.acceleration.tolist()})"
                )

    def box(
        self, q: np.ndarray, lower: np.ndarray, upper: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The joint limits [lower, upper] narrowed to what one period can reach from q.

        Args:
            q: joint positions at the start of the period, shape (nq,) [rad or m].
            lower: lower joint limits, shape (nq,) [rad or m] (−inf: none).
            upper: upper joint limits, shape (nq,) [rad or m] (+inf: none).

        Returns:
            The narrowed (lower, upper) bounds, each shape (nq,) [rad or m].
        """
        reach = (1.0 - ROUND_OFF) * self.velocity * self.dt
        change = self.change
        last = np.zeros_like(q) if self._last_motion is None else self._last_motion
        low, high, self.strained = _box(
            q, lower, upper, reach, np.full_like(q, np.inf) if change is None else change, last
        )
        return low, high

    def record(self, motion: np.ndarray) -> None:
        """Remember the motion of the period that ended (for the acceleration limit).

        Args:
            motion: joint displacement over that period, shape (nq,) [rad or m].
        """
        self._last_motion = np.array(motion, dtype=float)

    @property
    def change(self) -> np.ndarray | None:
        """Each joint's largest change of motion per period, a·dt² [rad or m]; None without
        an acceleration limit."""
        if self.acceleration is None:
            return None
        return (1.0 - ROUND_OFF) * self.acceleration * self.dt**2

    @property
    def last_motion(self) -> np.ndarray | None:
        """The joint motion of the period that ended [rad or m]; None: at rest."""
        return self._last_motion

    def reset(self) -> None:
        """Forget the last motion: the arm starts at rest."""
        self._last_motion = None
        self.strained = False


@jit()
def _box(q, lower, upper, reach, change, last):
    """RateLimits.box in one compiled call: (lower, upper, strained); change is inf for a joint
    without an acceleration limit."""
    n = q.size
    low, high = np.empty(n), np.empty(n)
    strained = False
    for j in range(n):
        lo = max(-reach[j], lower[j] - q[j])
        hi = min(reach[j], upper[j] - q[j])
        c = change[j]
        if math.isfinite(c):
            lo = max(lo, -_braking_reach(q[j] - lower[j], c))
            hi = min(hi, _braking_reach(upper[j] - q[j], c))
            fast_lo, fast_hi = max(lo, last[j] - c), min(hi, last[j] + c)
            if fast_lo > fast_hi:  # the acceleration box misses the rest: its nearest point
                strained = True
                fast_lo = fast_hi = min(max(last[j], lo), hi)
            lo, hi = fast_lo, fast_hi
        low[j] = q[j] + lo
        high[j] = q[j] + max(hi, lo)
    return low, high, strained


@jit()
def _braking_reach(room: float, change: float) -> float:
    """The largest motion m [rad] toward a limit `room` away that can still stop before it,
    m + m²/(2c) ≤ room with c the largest change of motion per period; room itself (≤ 0: back
    inside) where the limit is reached or unbounded."""
    if room <= 0.0 or not math.isfinite(room):
        return room
    return change * (math.sqrt(1.0 + 2.0 * room / change) - 1.0)
