"""The fake UR controller's state and its 2 ms cycle: the program (program.py) on the RTDE
registers, the servo toward servoJ's target, the safety checks a real controller makes, and
the MuJoCo twin of the arm (sim.twin) under it.

servoJ is modelled as a rate-limited first-order follower: the commanded joint speed is the
target's distance over lookahead_time, within each joint's speed limit, changing by at most
its acceleration limit per second (UR documents lookahead_time as smoothing and gain as a
proportional gain; the fake checks gain within its range and does not use it otherwise).

What it enforces, as a real controller does:
- a servoJ target outside the joint limits, a commanded motion that could not brake before
  a limit, or a target farther from the commanded position than
  JUMP × the joint's speed limit × lookahead_time (a jump in the set-point: more than the
  follower's own lag at full speed), is a protective stop: the arm brakes, the program
  pauses, safety_status_bits says so;
- the RTDE watchdog (setWatchdog): when the watched input register is not written at the set
  frequency, the program stops and the arm brakes;
- stopScript, servoStop, stopL / stopJ, the dashboard's `stop`: the arm brakes.
Every stop brakes each joint at the robot's acceleration limit (arms.braking).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from articula.arms.braking import brake_step
from articula.arms.ur_fake.program import ControlProgram, NotModelledError
from articula.arms.ur_fake.rtde_types import FORMATS, INPUTS, OUTPUTS
from articula.scene.scene import Scene
from articula.sim.twin import ServoGains, Twin

__all__ = ["PAUSED", "PLAYING", "RATE", "STOPPED", "Controller", "Event"]

RATE = 500.0  # [Hz] an e-Series controller's cycle
STOPPED, PLAYING, PAUSED = 1, 2, 4  # runtime_state
JUMP = 2.0  # a servoJ target this many times the follower's lag at full speed away is a jump
LOOKAHEAD, GAIN = (0.03, 0.2), (100.0, 2000.0)  # servoj's ranges
NORMAL, PROTECTIVE = 1, 3  # safety_mode


@dataclass(frozen=True)
class Event:
    """Something the controller did that a log shows.

    Attributes:
        t: controller time [s].
        text: what happened, one line.
    """

    t: float
    text: str


def _zero(kind: str) -> object:
    width = FORMATS[kind][:-1]
    return (0,) * int(width) if width else 0


class Controller:
    """A UR controller's registers, program, safety and arm, one cycle per `tick`.

    Args:
        scene: the arm (six revolute joints) and its obstacles.
        q0: where the arm is at power-on, at rest, shape (6,) [rad].
        gains: the twin's joint servos.
        on_event: called with each Event as it happens.

    Attributes:
        t: controller time [s].
        runtime_state: STOPPED, PLAYING or PAUSED.
        protective: in a protective stop.
        events: every Event so far.
        log: each cycle's (t, measured q (6,), commanded q (6,), runtime_state, contacts).
        contacts: the most contacts MuJoCo saw in a cycle.
        lock: held while a cycle runs or registers are written.
    """

    def __init__(
        self,
        scene: Scene,
        q0: np.ndarray,
        gains: ServoGains | None = None,
        on_event: Callable[[Event], None] | None = None,
    ) -> None:
        self.robot = scene.robot
        self.twin = Twin(scene, RATE, gains)
        self.twin.reset(np.asarray(q0, dtype=float))
        self.q_cmd, self.qd_cmd = self.twin.q, np.zeros(len(q0))
        self.h, self.t = 1.0 / RATE, 0.0
        self.lock = threading.Lock()
        self.changed = threading.Condition(self.lock)
        self._inputs = {name: _zero(kind) for name, kind in INPUTS.items()}
        self._silence = 0.0  # [s] on-time cycles since the watched register was written
        self._outputs = {name: _zero(kind) for name, kind in OUTPUTS.items()}
        self.program: ControlProgram | None = None
        self.runtime_state, self.protective = STOPPED, False
        self._servo: tuple[np.ndarray, float] | None = None
        self._braking = False
        self._watchdog: tuple[str, float] | None = None
        self.events: list[Event] = []
        self.log: list[tuple[float, np.ndarray, np.ndarray, int, int]] = []
        self.contacts = 0
        self._on_event = on_event

    # -- what the program reads and does (program.Registers) --------------------------------

    def input_int(self, index: int) -> int:
        """input_int_register_{index}.

        Args:
            index: the register's number (0–47).

        Returns:
            Its value.
        """
        return int(self._inputs[f"input_int_register_{index}"])  # type: ignore[call-overload]

    def input_double(self, index: int) -> float:
        """input_double_register_{index}.

        Args:
            index: the register's number (0–47).

        Returns:
            Its value.
        """
        return float(self._inputs[f"input_double_register_{index}"])  # type: ignore[arg-type]

    def set_output_int(self, index: int, value: int) -> None:
        """Write output_int_register_{index}.

        Args:
            index: the register's number (0–47).
            value: its new value.
        """
        self._outputs[f"output_int_register_{index}"] = int(value)

    def servoj(self, q: list[float], t: float, lookahead_time: float, gain: float) -> None:
        """Servo toward q; lookahead_time and gain are checked within servoj's ranges (a
        value outside stops the program, as a runtime error).

        Args:
            q: the target joints, six values [rad].
            t: the call's blocking time [s] (one cycle here).
            lookahead_time: servoj's smoothing time [s] (the follower's time constant).
            gain: servoj's proportional gain (checked, not used).
        """
        if not LOOKAHEAD[0] <= lookahead_time <= LOOKAHEAD[1] or not GAIN[0] <= gain <= GAIN[1]:
            self._stop_program(
                f"servoj: lookahead_time {lookahead_time:g} s or gain {gain:g} outside "
                f"[{LOOKAHEAD[0]}, {LOOKAHEAD[1]}] s, [{GAIN[0]:g}, {GAIN[1]:g}]"
            )
            return
        self._servo = (np.array(q, dtype=float), lookahead_time)

    def brake(self, why: str) -> None:
        """Stop servoing and bring the arm to rest.

        Args:
            why: what asked for it, for the log.
        """
        if self._servo is not None or np.any(self.qd_cmd):
            self._event(f"{why}: braking")
        self._servo, self._braking = None, True

    def set_watchdog(self, register: str, frequency: float) -> None:
        """Stop the program when `register` is not written at least at `frequency`.

        Args:
            register: the watched input variable's name.
            frequency: the least rate it must be written at [Hz].
        """
        self._watchdog, self._silence = (register, frequency), 0.0
        self._event(f"RTDE watchdog on {register} at {frequency:g} Hz")

    def protective_stop(self, why: str) -> None:
        """Brake, pause the program, flag the protective stop.

        Args:
            why: the cause, for the log.
        """
        self.protective = True
        self._servo, self._braking = None, True
        if self.runtime_state == PLAYING:
            self.runtime_state = PAUSED
        self._event(f"protective stop: {why}")

    # -- what the network side does ---------------------------------------------------------

    def write_inputs(self, values: dict[str, object]) -> None:
        """A client's data package: its variables' new values (call it holding the lock).

        Args:
            values: input variable name -> its value.
        """
        self._inputs.update(values)
        if self._watchdog is not None and self._watchdog[0] in values:
            self._silence = 0.0

    def run_program(self, program: ControlProgram | None, name: str) -> None:
        """A program arrived on a script port: the running one stops, this one plays.

        Args:
            program: ur-rtde's control program, or None for one the fake cannot run (which
                it says and ignores).
            name: the program's name (`def name():`), for the log.
        """
        if self.runtime_state != STOPPED:
            self._stop_program("a new program replaces it")
        if program is None:
            self._event(f"program {name!r} is not ur-rtde's control script: not modelled")
            return
        if self.protective:
            self._event(f"program {name!r} refused: in a protective stop")
            return
        self.program, self.runtime_state = program, PLAYING
        self._watchdog = None
        program.start(self)
        self._event(f"program {name!r} playing")

    def stop_program(self, why: str) -> None:
        """Stop the program and brake (the dashboard's `stop`).

        Args:
            why: what asked for it, for the log.
        """
        self._stop_program(why)

    def unlock_protective_stop(self) -> None:
        """Leave a protective stop once the arm is at rest (the program stays stopped)."""
        if self.protective and not self._braking:
            self.protective = False
            self._stop_program("protective stop unlocked")

    # -- the cycle --------------------------------------------------------------------------

    def tick(self, on_time: bool = True) -> dict[str, object]:
        """One 2 ms cycle (call it holding the lock).

        Args:
            on_time: the cycle runs at its time; False for one of a burst by which a fake
                that fell behind catches up (no client could write between those, so the
                watchdog does not count them: a real controller never falls behind).

        Returns:
            Every output variable's value now, for the RTDE sessions.
        """
        if self.program is not None and self.runtime_state == PLAYING:
            try:
                if not self.program.cycle(self):
                    self._stop_program("stopScript")
            except NotModelledError as exc:
                self._stop_program(str(exc))
        self._check_watchdog(on_time)
        self._move()
        self.twin.place_obstacles(self.t + self.h)
        self.twin.step(self.q_cmd, self.qd_cmd)
        self.t += self.h
        contacts = self.twin.contacts()
        self.contacts = max(self.contacts, contacts)
        q = self.twin.q
        self.log.append((self.t, q, self.q_cmd.copy(), self.runtime_state, contacts))
        self.changed.notify_all()
        return self._output_values(q)

    def _move(self) -> None:
        """The commanded motion this cycle: toward servoJ's target, braking, or held."""
        previous = self.qd_cmd
        if self._braking:
            self.q_cmd, self.qd_cmd = brake_step(
                self.q_cmd, self.qd_cmd, self.robot.acceleration_limit, self.h
            )
            self._braking = bool(np.any(self.qd_cmd))
        elif self._servo is not None and self.runtime_state == PLAYING:
            target, lookahead = self._servo
            if self._safe(target, lookahead):
                robot, step = self.robot, self.robot.acceleration_limit * self.h
                wanted = np.clip((target - self.q_cmd) / lookahead, -robot.velocity_limit,
                                 robot.velocity_limit)  # fmt: skip
                self.qd_cmd = self.qd_cmd + np.clip(wanted - self.qd_cmd, -step, step)
                self.q_cmd = self.q_cmd + self.qd_cmd * self.h
        else:
            self.qd_cmd = np.zeros_like(self.qd_cmd)
        self._qdd = (self.qd_cmd - previous) / self.h

    def _safe(self, target: np.ndarray, lookahead: float) -> bool:
        """Whether a servoJ target keeps the joint limits and is no jump (else a protective
        stop)."""
        robot, names, qd = self.robot, self.robot.joint_names, self.qd_cmd
        # where the commanded motion would stop if it braked after this cycle
        stop = self.q_cmd + qd * self.h + qd * np.abs(qd) / (2 * robot.acceleration_limit)
        for q, what in ((target, "set-point"), (stop, "braking from its motion")):
            outside = np.flatnonzero((q < robot.lower) | (q > robot.upper))
            if outside.size:
                j = int(outside[0])
                self.protective_stop(
                    f"{names[j]} {what} reaches {q[j]:.4f} rad, outside its limits "
                    f"[{robot.lower[j]:.4f}, {robot.upper[j]:.4f}]"
                )
                return False
        gap = np.abs(target - self.q_cmd)
        over = np.flatnonzero(gap > JUMP * robot.velocity_limit * lookahead)
        if over.size:
            j = int(over[0])
            self.protective_stop(
                f"{names[j]} set-point jumps {gap[j]:.4f} rad from the commanded "
                f"{self.q_cmd[j]:.4f} rad (more than {JUMP:g} × {robot.velocity_limit[j]:.2f} "
                f"rad/s × lookahead {lookahead:g} s)"
            )
            return False
        return True

    def _check_watchdog(self, on_time: bool) -> None:
        if self._watchdog is None or self.runtime_state != PLAYING:
            return
        register, frequency = self._watchdog
        self._silence += self.h if on_time else 0.0
        if frequency > 0 and self._silence > 1.0 / frequency:
            self._stop_program(
                f"RTDE watchdog: {register} not written for {1e3 * self._silence:.0f} ms "
                f"(at least {frequency:g} Hz asked)"
            )

    def _stop_program(self, why: str) -> None:
        if self.runtime_state != STOPPED:
            self._event(f"program stopped: {why}")
        self.program, self.runtime_state, self._watchdog = None, STOPPED, None
        self._servo, self._braking = None, True

    def _event(self, text: str) -> None:
        event = Event(self.t, text)
        self.events.append(event)
        if self._on_event is not None:
            self._on_event(event)

    def _output_values(self, q: np.ndarray) -> dict[str, object]:
        """The output variables this cycle (those not modelled stay zero)."""
        out = self._outputs
        out["timestamp"] = self.t
        out["target_q"], out["target_qd"] = tuple(self.q_cmd), tuple(self.qd_cmd)
        out["target_qdd"] = tuple(self._qdd)
        out["actual_q"], out["actual_qd"] = tuple(q), tuple(self.twin.data.qvel)
        out["target_moment"] = tuple(self.twin.torque)
        out["actual_TCP_pose"] = _pose(self.robot.ee_pose(q))
        out["target_TCP_pose"] = _pose(self.robot.ee_pose(self.q_cmd))
        out["robot_mode"], out["joint_mode"] = 7, (253,) * 6  # RUNNING
        out["safety_mode"] = PROTECTIVE if self.protective else NORMAL
        out["safety_status_bits"] = (1 << 2) if self.protective else 1
        out["runtime_state"] = self.runtime_state
        out["robot_status_bits"] = 1 | (2 if self.runtime_state == PLAYING else 0)
        out["speed_scaling"] = out["target_speed_fraction"] = 1.0
        return out


def _pose(T: np.ndarray) -> tuple[float, ...]:
    """A 4×4 pose as UR's [x, y, z, rx, ry, rz] (position [m], rotation vector [rad])."""
    return (*T[:3, 3], *pin.log3(T[:3, :3]))
