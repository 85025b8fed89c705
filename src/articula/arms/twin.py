"""The MuJoCo twin (sim.twin) as an Arm: each set-point is one tick of the twin's servos, its
time the ticks played; stop brakes the commanded motion at the robot's acceleration limits.
Imports MuJoCo (the `sim` extra)."""

from __future__ import annotations

import numpy as np

from articula.arms.arm import Measured
from articula.arms.braking import braking_ticks
from articula.scene.scene import Scene
from articula.sim.twin import ServoGains, Twin
from articula.sim.twin_arm import SETTLE

__all__ = ["TwinServo"]


class TwinServo:
    """The twin of a scene's arm, one servo tick per set-point.

    Args:
        scene: the robot and its obstacles.
        q0: where the arm starts, at rest, shape (n,) [rad] (on any branch: a continuous
            joint a turn off stays a turn off).
        rate: the servo rate [Hz].
        gains: the joint servos' gains.

    Attributes:
        rate: the servo rate [Hz].
        twin: the MuJoCo twin.
        t: the twin's time: ticks played / rate [s].
        contacts: the most contacts MuJoCo saw at any tick so far.
    """

    def __init__(
        self, scene: Scene, q0: np.ndarray, rate: float, gains: ServoGains | None = None
    ) -> None:
        self.rate = float(rate)
        self.twin = Twin(scene, rate, gains)
        self._q0 = np.array(q0, dtype=float)
        self._deceleration = scene.robot.acceleration_limit
        self._last = (self._q0.copy(), np.zeros_like(self._q0))
        self.t, self.contacts = 0.0, 0

    def connect(self) -> Measured:
        """Put the twin at rest at q0 at time 0.

        Returns:
            The first measurement.
        """
        self.twin.reset(self._q0)
        self.t, self.contacts = 0.0, 0
        return self.read()

    def read(self) -> Measured:
        """The twin's joints now.

        Returns:
            Its time [s] and joints [rad].
        """
        return Measured(self.t, self.twin.q)

    def send(self, q: np.ndarray, qd: np.ndarray) -> None:
        """Play one tick toward the set-point.

        Args:
            q: joint positions, shape (n,) [rad].
            qd: joint velocities, shape (n,) [rad/s].
        """
        self.t += 1.0 / self.rate
        self.twin.place_obstacles(self.t)
        self.twin.step(q, qd)
        self.contacts = max(self.contacts, self.twin.contacts())
        self._last = (np.array(q, dtype=float), np.array(qd, dtype=float))

    def stop(self) -> None:
        """Brake the commanded motion at the acceleration limits, then hold it for SETTLE
        time constants of the servos (kv / kp) so that the measured arm, which lags its
        commands, comes to rest too."""
        q, qd = self._last
        for q_ref, qd_ref in braking_ticks(q, qd, self._deceleration, 1.0 / self.rate):
            self.send(q_ref, qd_ref)
        hold = int(np.ceil(SETTLE * np.max(self.twin.kv / self.twin.kp) * self.rate))
        for _ in range(hold):
            self.send(self._last[0], np.zeros_like(self._last[0]))

    def close(self) -> None:
        """Nothing to close: the twin lives in this process."""
