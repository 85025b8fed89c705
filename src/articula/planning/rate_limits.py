"""Joint speed and acceleration limits as a box the next configuration must stay in."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from articula.errors import ConfigError


@dataclass
class RateLimits:
    """Per-period bounds on joint motion.

    Attributes:
        velocity: the largest joint speeds [rad/s or m/s], one per joint (inf: none).
        dt: the control period [s].
        acceleration: the largest joint acceleration [rad/s² or m/s²] for every joint, or None.
    """

    velocity: np.ndarray
    dt: float
    acceleration: float | None = None
    _last_motion: np.ndarray | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self.velocity = np.asarray(self.velocity, dtype=float)
        if not (np.all(self.velocity > 0) and np.isfinite(self.dt) and self.dt > 0):
            raise ConfigError("RateLimits.velocity", "speeds and dt must be > 0")
        if self.acceleration is not None and not self.acceleration > 0:
            raise ConfigError("RateLimits.acceleration", f"must be > 0 (got {self.acceleration})")

    def box(
        self, q: np.ndarray, lower: np.ndarray, upper: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The joint limits [lower, upper] narrowed to what one period can reach from q.

        Args:
            q: joint positions at the start of the period, shape (nq,) [rad or m].
            lower: lower joint limits, shape (nq,) [rad or m].
            upper: upper joint limits, shape (nq,) [rad or m].

        Returns:
            The narrowed (lower, upper) bounds, each shape (nq,) [rad or m].
        """
        reach = self.velocity * self.dt
        low, high = -reach, reach
        if self.acceleration is not None and self._last_motion is not None:
            change = self.acceleration * self.dt**2
            low = np.maximum(low, self._last_motion - change)
            high = np.minimum(high, self._last_motion + change)
            high = np.maximum(high, low)  # a slowing motion can always stop within its reach
        return np.maximum(lower, q + low), np.minimum(upper, np.maximum(q + high, lower))

    def record(self, motion: np.ndarray) -> None:
        """Remember the motion of the period that ended (for the acceleration limit).

        Args:
            motion: joint displacement over that period, shape (nq,) [rad or m].
        """
        self._last_motion = np.array(motion, dtype=float)

    def reset(self) -> None:
        """Forget the last motion: the arm starts at rest."""
        self._last_motion = None
