"""`articula drive`: a plan config's planner driving an arm in real time (arms.ServoLoop), and
the run folder of what the arm measured.

The arm's measured start is checked against the scene's robot.q0 before anything moves
(continuous joints the short way round): within `tolerance` the controller starts where the
arm is and its first periods close the offset toward the reference's start, within the
limits; beyond, the drive is refused naming the joint. Whatever
ends the run — its end, Ctrl-C, SIGTERM, a planner stall, a lost connection — the stream's
braking path brings the arm to rest first (if the arm still listens), and the run folder is
written; then the interruption or failure goes on.
"""

from __future__ import annotations

import contextlib
import signal
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from articula.arms.arm import Arm
from articula.arms.realtime import use_realtime
from articula.arms.servo_loop import ServoLoop
from articula.errors import ArticulaError, ConfigError, DeviceError
from articula.experiments.drive_record import DriveRun, write_drive
from articula.experiments.plan import PlanSetup, build_plan, load_plan
from articula.loops.online import MAX_LAG
from articula.loops.servo import ServoLimits, ServoStream, ticks_per_period
from articula.runs.folders import check_out
from articula.signals import Terminated

__all__ = ["START_TOLERANCE", "DriveOptions", "arm_from_spec", "check_start", "drive"]

START_TOLERANCE = 0.05  # [rad] the farthest a joint may be from robot.q0 for a drive to start
SIGNALS = (signal.SIGINT, signal.SIGTERM)


@dataclass(frozen=True)
class DriveOptions:
    """How to drive.

    Attributes:
        arm: "ur:HOST" (a UR through ur-rtde) or "twin" (the MuJoCo twin in this process).
        rate: the servo rate [Hz] (500 for a UR e-Series).
        tolerance: the farthest a joint may start from robot.q0 [rad].
        rt_priority: run the process under SCHED_FIFO at this priority once the planner is
            built (arms.realtime); None: ordinary scheduling.
    """

    arm: str
    rate: float = 500.0
    tolerance: float = START_TOLERANCE
    rt_priority: int | None = None


def arm_from_spec(spec: str, rate: float, plan: PlanSetup) -> Arm:
    """The arm an --arm value names.

    Args:
        spec: "ur:HOST" or "twin".
        rate: the servo rate [Hz].
        plan: the plan (the twin's scene, start and servos).

    Returns:
        The arm, not yet connected.
    """
    kind, _, host = spec.partition(":")
    if kind == "ur" and host:
        from articula.arms.ur import URArm

        return URArm(host, rate)
    if spec == "twin":
        from articula.arms.twin import TwinServo
        from articula.sim.twin import ServoGains

        plant = plan.config.plant
        gains = None if plant is None else ServoGains(plant.stiffness, plant.damping)
        return TwinServo(plan.scene, plan.q0, rate, gains)
    raise ConfigError(
        "--arm", f"give ur:HOST (a Universal Robots controller) or twin (got {spec!r})"
    )


def check_start(plan: PlanSetup, q: np.ndarray, tolerance: float) -> np.ndarray:
    """The arm's measured start against robot.q0.

    Args:
        plan: the plan (its robot and q0).
        q: the measured joints, shape (n,) [rad], on the arm's branch.
        tolerance: the farthest a joint may be from q0 [rad].

    Returns:
        How far each joint is from q0, shape (n,) [rad] (continuous joints the short way).

    Raises:
        ConfigError: naming robot.q0, the joint and both values, when one is beyond.
    """
    robot = plan.scene.robot
    q = np.asarray(q, dtype=float)
    if q.shape != plan.q0.shape:
        raise ConfigError(
            f"{plan.where}: robot.urdf",
            f"the arm has {q.size} joints, the scene's robot {plan.q0.size}",
        )
    off = np.where(robot.continuous, robot.difference(q, plan.q0), q - plan.q0)
    j = int(np.argmax(np.abs(off)))
    if abs(off[j]) > tolerance:
        raise ConfigError(
            f"{plan.where}: robot.q0",
            f"the arm's {robot.joint_names[j]} is at {q[j]:.4f} rad, robot.q0 has "
            f"{plan.q0[j]:.4f} rad: {abs(off[j]):.4f} rad apart, beyond --start-tolerance "
            f"{tolerance:g} rad; move the arm to robot.q0 first, or set robot.q0 to where it is",
        )
    return off


def drive(
    scene_file: Path,
    options: DriveOptions,
    out: Path,
    force: bool = False,
    announce: Callable[[str], None] = lambda line: None,
) -> dict[str, Any]:
    """Drive the arm along the scene's plan in real time and write the run folder.

    Args:
        scene_file: the plan config ([robot], [trajectory], [planner], ...).
        options: the arm, servo rate and start tolerance.
        out: the run folder to write.
        force: write into a folder holding files articula did not write.
        announce: called with a line once the arm streams.

    Returns:
        The run's record (record.json).

    Raises:
        ConfigError: bad input, or an arm beyond the start tolerance (nothing moved).
        DeviceError: the arm failed or the connection was lost (the folder is written).
        StallError: the planner fell behind the stream (the arm braked; the folder is written).
    """
    data = load_plan(scene_file)
    where = str(scene_file)
    plan = build_plan(data, scene_file.parent, where)
    dt = plan.spec.dt
    try:
        ticks_per_period(options.rate, dt)
    except ConfigError as exc:
        raise ConfigError("--rate", exc.problem) from None
    check_out(out, "run", force)
    controller = plan.controller()  # its kernels compiled before the arm's watchdog runs
    if options.rt_priority is not None:  # after the compiling: a real-time compiler hogs a core
        use_realtime(options.rt_priority)
    arm = arm_from_spec(options.arm, options.rate, plan)
    start = arm.connect()
    try:
        offset = check_start(plan, start.q, options.tolerance)
        # From where the arm is: the first periods close the offset within the limits, toward
        # the reference's start (the tool at q0). A reset takes milliseconds; the controller's
        # watchdog is already counting.
        controller.reset(plan.scene.robot.wrap(start.q))
    except BaseException:
        arm.stop()
        arm.close()
        raise
    robot = plan.scene.robot
    stream = ServoStream(ServoLimits.of(robot), dt, options.rate)
    loop = ServoLoop(arm, stream, robot, start)
    run = DriveRun(plan, options, loop, offset)
    periods = int(np.ceil((plan.reference.duration + plan.spec.duration) / dt - 1e-9))
    started = time.monotonic()
    announce(f"streaming to {options.arm} at {options.rate:g} Hz for {periods * dt:g} s")
    failure: BaseException | None = None
    with _signals_noted() as signals:  # raised between periods, never inside a kernel
        try:
            for k in range(periods):
                if signals:
                    raise _as_exception(signals[0])
                played, measured = loop.measurement()  # it answers period played - 1's target
                lag = min(max(k - played, 0), MAX_LAG)
                began = time.perf_counter()
                q = controller.step(
                    plan.reference(k * dt), q_measured=robot.wrap(measured.q), lag=lag
                )
                run.step_s.append(time.perf_counter() - began)
                loop.push(q)
                run.setpoints.append(q)
        except (KeyboardInterrupt, Terminated, ArticulaError) as exc:
            failure = exc
        try:
            if failure is None:
                loop.finish()  # the queued set-points, then the braking path
            else:
                loop.stop()  # the braking path from where the stream is
        except DeviceError as exc:
            failure = failure or exc
        with contextlib.suppress(RuntimeError):  # a controller that is gone has nothing to close
            arm.close()
        if failure is None and signals:  # a signal during the braking path: it was not cut
            failure = _as_exception(signals[0])
    record = write_drive(out, data, run, _outcome(failure), time.monotonic() - started, force)
    if failure is not None:
        raise failure
    return record


@contextlib.contextmanager
def _signals_noted() -> Iterator[list[int]]:
    """Within the block, SIGINT and SIGTERM are noted, not raised: a signal raised inside a
    compiled kernel would surface as a SystemError, and the braking path must not be cut.

    Yields:
        The signals received so far (the list grows).
    """
    noted: list[int] = []
    previous = {s: signal.signal(s, lambda n, _: noted.append(n)) for s in SIGNALS}
    try:
        yield noted
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


def _as_exception(signum: int) -> BaseException:
    """What the CLI makes of a signal: Ctrl-C (130) or SIGTERM (143)."""
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated()


def _outcome(failure: BaseException | None) -> str:
    """The run's outcome, for its record."""
    if failure is None:
        return "done"
    if isinstance(failure, KeyboardInterrupt):
        return "interrupted (Ctrl-C)"
    if isinstance(failure, Terminated):
        return "terminated (SIGTERM)"
    return str(failure)
