"""A plan's arm as the twin: each period's command streamed to the servo rate and played on the
MuJoCo twin, the joints it measures handed back to the planner (loops.tracking.track's `arm`),
the stream's braking tail played after the run, and what the twin did recorded for the run's
trace and metrics: the measured tool against the reference at the same time, the measured
clearances at every servo tick, the time a joint spent at its effort limit.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from articula.loops.sampled_clearance import PLANT_TOLERANCE, clearance_failure, sampled_clearance
from articula.loops.servo import ServoLimits, ServoStream
from articula.loops.tracking import PlanResult
from articula.scene.scene import Scene
from articula.sim.twin import ServoGains, Twin

__all__ = ["SATURATED", "SETTLE", "TwinArm"]

SATURATED = 1.0 - 1e-6  # |torque| / effort from which a joint counts as at its effort limit
SETTLE = 5.0  # servo time constants the arm is held at the tail's end: e⁻⁵ of its speed left


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
        contacts: the most contacts MuJoCo saw during each period so far (the tail's too).
        peak_torque: each joint's largest |torque| over every tick so far [N·m].
        ticks: the joints measured at every tick so far, the tail's too, one (n,) row each.
        saturated: each joint at its effort limit at each tick so far, one (n,) row each.
        tail_periods: how many periods of the stream's braking tail were played (`brake`).
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
        self.joint_names = list(scene.robot.joint_names)
        self._sent = q0  # the last set-point streamed (continuous joints unwrapped) [rad]
        self.measured: list[np.ndarray] = []
        self.torque: list[np.ndarray] = []
        self.contacts: list[int] = []
        self.peak_torque = np.zeros(len(q0))
        self.ticks: list[np.ndarray] = [np.asarray(q0, dtype=float).copy()]
        self.saturated: list[np.ndarray] = []
        self.tail_periods = 0

    def __call__(self, command: np.ndarray) -> np.ndarray:
        """Play one period's command on the twin.

        Args:
            command: the period's joint set-point, shape (n,) [rad]; a continuous joint is
                streamed the shortest way round from the last set-point, as run_stream does.

        Returns:
            The joints measured at the end of the period, shape (n,) [rad] (continuous
            joints wrapped to (−π, π]).
        """
        robot = self._robot
        # A command that wraps at ±π is the same pose: streamed as is, the servo would turn
        # the joint a whole turn the long way.
        turned = self._sent + robot.difference(command, self._sent)
        self._sent = np.where(robot.continuous, turned, command)  # the others exactly as sent
        self._play(self._sent)
        self.measured.append(robot.wrap(self.twin.q))
        self.torque.append(self.twin.torque)
        return self.measured[-1]

    def brake(self) -> None:
        """Play the stream's braking tail after the run: the set-points that bring the arm to
        rest (ServoStream.stopping_points, what the stream sends after the last set-point),
        then the last one held for SETTLE time constants of the servo (kv / kp [s]) so that
        the measured arm, which lags its stream, comes to rest too. Its ticks count in the
        metrics; the trace keeps one row per planned period."""
        points = self.stream.stopping_points()
        hold = int(np.ceil(SETTLE * np.max(self.twin.kv / self.twin.kp) / self.stream.dt))
        points = np.vstack([points, np.tile(points[-1], (hold, 1))])
        for point in points:
            self._play(point)
        self.tail_periods += len(points)

    def _play(self, command: np.ndarray) -> None:
        """One period's ticks toward `command`, each tick's measurement recorded."""
        twin, most, stream = self.twin, 0, self.stream
        start = len(self.contacts) * stream.dt  # this period's time [s]
        for i, (q_ref, qd_ref, _) in enumerate(stream.period(command)):
            twin.place_obstacles(start + (i + 1) * stream.dt / stream.ticks)
            twin.step(q_ref, qd_ref)
            most = max(most, twin.contacts())
            torque = np.abs(twin.data.qfrc_actuator)
            np.maximum(self.peak_torque, torque, out=self.peak_torque)
            self.saturated.append(torque >= SATURATED * twin.effort)
            self.ticks.append(twin.q)
        self.contacts.append(most)

    @property
    def periods(self) -> int:
        """The periods every per-period list (measured, torque, contacts) holds."""
        return min(len(self.measured), len(self.torque), len(self.contacts))

    def truncate(self, periods: int) -> None:
        """Keep only the first `periods` periods of measured, torque and contacts: a live
        session stopped by a signal between two of their appends keeps the periods every
        column reached. The ticks, their saturation and the peak torque keep every tick
        played (the arm was there).

        Args:
            periods: how many periods to keep.
        """
        del self.measured[periods:], self.torque[periods:], self.contacts[periods:]

    @property
    def speed(self) -> np.ndarray:
        """The measured joint speeds now, shape (n,) [rad/s]."""
        return self.twin.data.qvel.copy()

    def columns(self) -> dict[str, np.ndarray]:
        """The trace's columns of the twin: qm_1..qm_n [rad], tau_1..tau_n [N·m], contacts.

        Returns:
            Column name -> one value per planned period.
        """
        measured, torque = np.array(self.measured), np.array(self.torque)
        columns = {f"qm_{j + 1}": measured[:, j] for j in range(measured.shape[1])}
        columns |= {f"tau_{j + 1}": torque[:, j] for j in range(torque.shape[1])}
        periods = len(self.measured)
        return columns | {"contacts": np.array(self.contacts[:periods], dtype=float)}

    def metrics(
        self,
        run: PlanResult,
        scene: Scene,
        settle: float,
        clearance: np.ndarray | None = None,
    ) -> dict[str, Any]:
        """What the twin did, against the run's reference.

        Args:
            run: the tracking run (its reference and times).
            scene: the scene, for the measured clearance and tool.
            settle: time after the path's start from which the run counts as settled [s].
            clearance: the measured arm's clearance each period, where the obstacles were
                then [m]; None: at every tick (the tail's too), from the scene's obstacle
                motion.

        Returns:
            plant_rms_error and plant_max_error (the tool measured at the end of each period
            against the reference at that same time, once settled [m]; the braking tail
            is not tracking and does not count); plant_min_clearance and
            plant_min_self_clearance (articula's clearances at the measured joints [m],
            with the pair and time, as loops.sampled_clearance.sampled_clearance);
            plant_contacts (periods, the tail's too, in which MuJoCo saw a contact);
            max_torque_ratio (largest |torque| / effort limit at any tick);
            torque_saturated_s (time with some joint at its effort limit [s]),
            torque_saturated_joint and torque_saturated_joint_s (the joint longest at its
            limit and that time [s]; None and 0 when none); plant_tail_s (the braking tail
            played [s]) and plant_final_speed (largest measured joint speed at the end
            [rad/s]).
        """
        robot, h = scene.robot, self.stream.dt / self.stream.ticks
        tool = np.array([robot.ee_position(q) for q in self.measured[:-1]])
        # The measurement at the end of period k is at run.t[k + 1], where the reference
        # is run.x_ref[k + 1]; the last period's end has no reference in the run.
        settled = run.t[1:] >= run.path_start + settle
        error = np.linalg.norm(tool - run.x_ref[1:], axis=1)[settled] if len(tool) else tool
        t_ticks = np.arange(len(self.ticks)) * h
        metrics = sampled_clearance(scene, np.array(self.ticks), t_ticks, "plant")
        if clearance is not None:  # the obstacles were where the caller measured them
            metrics |= {"plant_min_clearance": float(np.min(clearance))}
            metrics |= {"plant_min_clearance_pair": None, "plant_min_clearance_at": None}
        saturated = np.array(self.saturated).reshape(-1, len(self.joint_names))
        per_joint = h * np.count_nonzero(saturated, axis=0)
        worst = int(np.argmax(per_joint))
        return metrics | {
            "plant_rms_error": float(np.sqrt(np.mean(error**2))) if error.size else 0.0,
            "plant_max_error": float(np.max(error, initial=0.0)),
            "plant_contacts": float(np.count_nonzero(self.contacts)),
            "max_torque_ratio": float(np.max(self.peak_torque / self.twin.effort)),
            "torque_saturated_s": float(h * np.count_nonzero(saturated.any(axis=1))),
            "torque_saturated_joint": self.joint_names[worst] if per_joint[worst] else None,
            "torque_saturated_joint_s": float(per_joint[worst]),
            "plant_tail_s": self.tail_periods * self.stream.dt,
            "plant_final_speed": float(np.max(np.abs(self.speed))),
        }

    @staticmethod
    def failure(
        metrics: dict[str, Any], tolerance: float, floors: tuple[float, float]
    ) -> str | None:
        """Why the twin's run failed, or None when it did not: a joint at its effort limit, a
        measured clearance below its floor by more than PLANT_TOLERANCE, or the measured
        tool's RMS error beyond the tolerance. A contact is not judged here: it exits 4.

        Args:
            metrics: the run's metrics, with those of `metrics`.
            tolerance: planner.tolerance, the RMS error a run may have once settled [m].
            floors: (planner.d_min, robot.self_d_min) [m].

        Returns:
            One line naming what failed and by how much; None: nothing did.
        """
        if metrics["plant_contacts"]:
            return None
        if metrics["torque_saturated_s"] > 0:
            return (
                f"the twin's {metrics['torque_saturated_joint']} was at its effort limit for "
                f"{metrics['torque_saturated_joint_s']:.3f} s (some joint for "
                f"{metrics['torque_saturated_s']:.3f} s): the motion asks more torque than "
                "the URDF's effort allows; lower robot.acceleration_limits, "
                "robot.jerk_limits or plant.stiffness, or check the URDF's effort limits"
            )
        cleared = clearance_failure(
            metrics, "plant", "the twin's measured arm", floors, PLANT_TOLERANCE
        )
        if cleared is not None:
            return cleared
        if metrics["plant_rms_error"] > tolerance:
            return (
                f"the twin's measured tool is {1e3 * metrics['plant_rms_error']:.2f} mm RMS "
                f"(max {1e3 * metrics['plant_max_error']:.2f} mm) off the reference, more than "
                f"planner.tolerance = {1e3 * tolerance:g} mm"
            )
        return None
