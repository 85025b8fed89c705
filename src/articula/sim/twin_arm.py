"""A plan's arm as the twin: each period's command streamed to the servo rate and played on the
MuJoCo twin, the joints it measures handed back to the planner (loops.tracking.track's `arm`),
and what the twin did recorded for the run's trace and metrics.
"""

from __future__ import annotations

import numpy as np

from articula.loops.servo import ServoLimits, ServoStream
from articula.loops.tracking import PlanResult
from articula.scene.scene import Scene
from articula.sim.twin import ServoGains, Twin

__all__ = ["TwinArm"]


class TwinArm:
    """The arm of a plan under rigid-body dynamics, one control period per call.

    Args:
        scene: the robot and its obstacles.
        q0: where the arm starts, at rest, shape (n,) [rad]; a continuous joint is started
            wrapped to (−π, π], as the controller and the plan's stream start it.
        dt: the control period [s].
        rate: the servo rate [Hz], a whole number of ticks per period.
        gains: the joint servos' gains.

    Attributes:
        twin: the MuJoCo twin.
        stream: the servo stream its commands go through.
        measured: the joints measured at the end of each period so far, one (n,) row each
            (continuous joints wrapped to (−π, π], as the commands are).
        torque: the joint torques at the end of each period so far [N·m].
        contacts: the most contacts MuJoCo saw during each period so far.
        peak_torque: each joint's largest |torque| over every tick so far [N·m].
    """

    def __init__(
        self,
        scene: Scene,
        q0: np.ndarray,
        dt: float,
        rate: float,
        gains: ServoGains | None = None,
    ) -> None:
        self._robot = scene.robot
        q0 = self._robot.wrap(np.asarray(q0, dtype=float))
        self.twin = Twin(scene, rate, gains)
        self.twin.reset(q0)
        self.stream = ServoStream(ServoLimits.of(scene.robot), dt, rate)
        self.stream.reset(q0)
        self._sent = q0  # the last set-point streamed (continuous joints unwrapped) [rad]
        self.measured: list[np.ndarray] = []
        self.torque: list[np.ndarray] = []
        self.contacts: list[int] = []
        self.peak_torque = np.zeros(len(q0))

    def __call__(self, command: np.ndarray) -> np.ndarray:
        """Play one period's command on the twin.

        Args:
            command: the period's joint set-point, shape (n,) [rad]; a continuous joint is
                streamed the shortest way round from the last set-point, as run_stream does.

        Returns:
            The joints measured at the end of the period, shape (n,) [rad] (continuous
            joints wrapped to (−π, π]).
        """
        robot, twin, most = self._robot, self.twin, 0
        # A command that wraps at ±π is the same pose: streamed as is, the servo would turn
        # the joint a whole turn the long way.
        turned = self._sent + robot.difference(command, self._sent)
        self._sent = np.where(robot.continuous, turned, command)  # the others exactly as sent
        start = len(self.measured) * self.stream.dt  # this period's time [s]
        for i, (q_ref, qd_ref, _) in enumerate(self.stream.period(self._sent)):
            twin.place_obstacles(start + (i + 1) * self.stream.dt / self.stream.ticks)
            twin.step(q_ref, qd_ref)
            most = max(most, twin.contacts())
            np.maximum(self.peak_torque, np.abs(twin.data.qfrc_actuator), out=self.peak_torque)
        self.measured.append(robot.wrap(twin.q))
        self.torque.append(twin.torque)
        self.contacts.append(most)
        return self.measured[-1]

    def columns(self) -> dict[str, np.ndarray]:
        """The trace's columns of the twin: qm_1..qm_n [rad], tau_1..tau_n [N·m], contacts.

        Returns:
            Column name -> one value per period.
        """
        measured, torque = np.array(self.measured), np.array(self.torque)
        columns = {f"qm_{j + 1}": measured[:, j] for j in range(measured.shape[1])}
        columns |= {f"tau_{j + 1}": torque[:, j] for j in range(torque.shape[1])}
        return columns | {"contacts": np.array(self.contacts, dtype=float)}

    def metrics(
        self,
        run: PlanResult,
        scene: Scene,
        settle: float,
        clearance: np.ndarray | None = None,
    ) -> dict[str, float]:
        """What the twin did, against the run's reference.

        Args:
            run: the tracking run (its reference and times).
            scene: the scene, for the measured clearance and tool.
            settle: time after the path's start from which the run counts as settled [s].
            clearance: the measured arm's clearance each period, where the obstacles were
                then [m]; None: found here from the scene's obstacle motion.

        Returns:
            plant_rms_error (the measured tool against the reference once settled [m]),
            plant_min_clearance (articula's clearance at the measured joints [m]),
            plant_contacts (periods in which MuJoCo saw a contact) and max_torque_ratio.
        """
        robot = scene.robot
        tool = np.array([robot.ee_position(q) for q in self.measured])
        settled = run.t >= run.path_start + settle
        error = np.linalg.norm(tool - run.x_ref, axis=1)[settled]
        if clearance is None:
            pairs = zip(self.measured, run.t, strict=True)
            clearance = np.array([scene.clearances(q, t)[0] for q, t in pairs])
        return {
            "plant_rms_error": float(np.sqrt(np.mean(error**2))) if error.size else 0.0,
            "plant_min_clearance": float(np.min(clearance)),
            "plant_contacts": float(np.count_nonzero(self.contacts)),
            "max_torque_ratio": float(np.max(self.peak_torque / self.twin.effort)),
        }
