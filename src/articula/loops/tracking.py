"""The arm's closed loop: a planner tracks a reference path over time; its metrics and trace."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError
from articula.limits import MAX_STEPS
from articula.loops.online import OnlineController
from articula.planning.approach import Trajectory
from articula.planning.planner import Planner
from articula.robots.model import RobotModel


@dataclass(frozen=True)
class PlanResult:
    """Time series of a tracking run: t [s], q [rad], x and x_ref [m], error [m], clearance to
    obstacles and between the checked link pairs [m].

    Attributes:
        t: time of each control period, shape (k,) [s].
        q: joint positions commanded each period, shape (k, n) [rad].
        x: end-effector position, shape (k, 3) [m].
        x_ref: reference position, shape (k, 3) [m].
        error: distance |x − x_ref|, shape (k,) [m].
        clearance: smallest link-obstacle signed distance each period, shape (k,) [m]; inf:
            no obstacle.
        planner_seconds: time spent in planner.step alone after the first period [s].
        first_period_seconds: the first period's time [s].
        q0: the start, shape (n,) [rad]; None: the first step's speed is unknown.
        orientation_error: orientation error, shape (k,) [rad], for a pose or axis task;
            else None.
        self_clearance: smallest signed distance between the links of a checked pair each
            period, shape (k,) [m]; None: no pair checked.
        path_start: when the path begins, after the approach from the tool [s]; 0: at once.
        infeasible: periods whose step could not keep every constraint (Planner.infeasible).
    """

    t: np.ndarray
    q: np.ndarray
    x: np.ndarray
    x_ref: np.ndarray
    error: np.ndarray
    clearance: np.ndarray
    planner_seconds: float
    first_period_seconds: float = 0.0
    q0: np.ndarray | None = None
    orientation_error: np.ndarray | None = None
    self_clearance: np.ndarray | None = None
    path_start: float = 0.0
    infeasible: int = 0


def track(
    planner: Planner,
    trajectory: Trajectory,
    q0: np.ndarray,
    dt: float,
    duration: float,
    max_steps: int = MAX_STEPS,
    progress: Callable[[int, int], None] | None = None,
    path_start: float = 0.0,
    arm: Callable[[np.ndarray], np.ndarray] | None = None,
) -> PlanResult:
    """Follow `trajectory` from q0 [rad] for `duration` [s], one step per `dt` [s] of an
    OnlineController, the object a live loop uses; with an `arm`, each period's command is
    sent to it and the joints it measures close the loop (OnlineController.step's q_measured).

    Args:
        planner: the planner that computes each period's configuration.
        trajectory: time [s] -> reference position (3,) [m] or a whole Target.
        q0: start joint positions, shape (n,) [rad], checked by OnlineController.reset.
        dt: control period [s].
        duration: length of the run [s], at least dt.
        max_steps: most periods allowed; a longer run is refused before anything is allocated.
        progress: called as progress(done, total) every hundredth of the run; None: silent.
        path_start: when the path itself begins (an Approach's duration) [s].
        arm: command (n,) [rad] -> the joints measured at the end of its period [rad]
            (sim.twin.TwinArm); None: the arm is where it was told.

    Returns:
        The run's time series (q: the commands).
    """
    if not (np.isfinite(dt) and dt > 0):
        raise ConfigError("dt", f"must be finite and > 0 s (got {dt})")
    if not (np.isfinite(duration) and duration >= dt):
        raise ConfigError("duration", f"must be finite and at least dt = {dt} s (got {duration})")
    if duration / dt > max_steps:
        raise ConfigError(
            "duration",
            f"{duration:g} s at dt = {dt:g} s is more than max_steps = {max_steps} periods; "
            "shorten it, raise dt or raise max_steps",
        )
    controller = OnlineController(planner, dt)
    q_start = controller.reset(q0)
    scene, robot = planner.scene, planner.scene.robot
    steps = round(duration / dt)
    t = np.arange(steps) * dt
    qs = np.empty((steps, q_start.size))
    x = np.empty((steps, 3))
    x_ref = np.empty((steps, 3))
    clearance = np.full(steps, np.inf)
    self_clearance = np.full(steps, np.inf) if scene.self_pairs else None
    task = planner.task
    orientation = np.zeros(steps) if task.kind != "position" else None
    planner_seconds = first_period_seconds = 0.0
    every = max(1, steps // 100)
    measured = None
    for n, tn in enumerate(t):
        if progress is not None and n % every == 0:
            progress(n, steps)
        target = trajectory(tn)
        start = time.perf_counter()
        q = controller.step(target, q_measured=measured)
        if n == 0:
            first_period_seconds = time.perf_counter() - start
        else:
            planner_seconds += time.perf_counter() - start
        measured = None if arm is None else arm(q)
        qs[n] = q
        pose = robot.ee_pose(q)
        x[n] = pose[:3, 3]
        x_ref[n] = controller.target.position
        if orientation is not None:
            orientation[n] = task.orientation_error(pose[:3, :3], controller.target)
        if scene.has_clearance:
            clearance[n], d_self = scene.clearances(q, tn)
            if self_clearance is not None:
                self_clearance[n] = d_self
    error = np.linalg.norm(x - x_ref, axis=1)
    return PlanResult(
        t,
        qs,
        x,
        x_ref,
        error,
        clearance,
        planner_seconds,
        first_period_seconds,
        q_start,
        orientation,
        self_clearance,
        path_start,
        planner.infeasible,
    )


# A joint at this share of its acceleration limit or more counts as saturated [-].
SATURATED = 0.9


def tracking_metrics(
    run: PlanResult, robot: RobotModel, settle: float, iterations: float, cone: float | None = None
) -> dict[str, float]:
    """Metrics of a tracking run.

    rms_error and max_error [m] after the path's start plus `settle` [s] (approach_s: when the
    path started); clearance [m] and colliding steps over the whole run and once settled (the
    approach from q0 is the riskiest part), between the checked link pairs too
    (min_self_clearance, self_collisions; None without pairs); joint-limit violations; the
    largest joint speed, acceleration and jerk over their limits (max_speed_ratio,
    max_acceleration_ratio, max_jerk_ratio) and how hard the settled commands use the
    acceleration limits (accel_rms_ratio, saturated_fraction: acceleration_use); the periods
    that could not keep every constraint (infeasible_steps); planner time per inner iteration
    (`iterations` in all) and per period [µs], both without the first period, and that
    period's time (first_period_ms).
    For a pose or axis task also rms_ and max_orientation_error [rad] after `settle`, and with
    a `cone` [rad] the settled steps whose tool axis is outside it (cone_violations).

    Args:
        run: the tracking run.
        robot: the robot, for its joint, speed and acceleration limits.
        settle: time after the path's start from which the run counts as settled [s].
        iterations: inner iterations (BAORNN) or solver calls (baselines) of the whole run.
        cone: allowed angle of the tool axis from its target [rad]; None: not counted.

    Returns:
        Metric name -> value, in the units above (times in [µs] or [ms] as named).
    """
    settled = run.t >= run.path_start + settle
    late = run.error[settled]
    timed = (len(run.t) - 1) / len(run.t)  # the share of the iterations after the first period
    outside = (run.q < robot.lower) | (run.q > robot.upper)
    extra = {}
    if run.orientation_error is not None:
        turned = run.orientation_error[settled]
        extra["rms_orientation_error"] = float(np.sqrt(np.mean(turned**2)))
        extra["max_orientation_error"] = float(turned.max())
        if cone is not None:
            extra["cone_violations"] = float(np.sum(turned > cone))
    return {
        "settle_s": settle,
        "rms_error": float(np.sqrt(np.mean(late**2))),
        "max_error": float(late.max()),
        "min_clearance": float(run.clearance.min()),
        "min_clearance_settled": float(run.clearance[settled].min()),
        "collisions": float(np.sum(run.clearance <= 0.0)),
        "collisions_settled": float(np.sum(run.clearance[settled] <= 0.0)),
        "min_self_clearance": None
        if run.self_clearance is None
        else float(run.self_clearance.min()),
        "self_collisions": None
        if run.self_clearance is None
        else float(np.sum(run.self_clearance <= 0.0)),
        "joint_limit_violations": float(np.sum(np.any(outside, axis=1))),
        "max_speed_ratio": max_speed_ratio(run, robot),
        "max_acceleration_ratio": max_acceleration_ratio(run, robot),
        "max_jerk_ratio": max_jerk_ratio(run, robot),
        **acceleration_use(run, robot, settled),
        "infeasible_steps": float(run.infeasible),
        "approach_s": run.path_start,
        # The planner alone: BAORNN's inner iterations, or a baseline's periods; the first
        # period, which compiles or loads the numba kernels of a fresh process, on its own.
        "time_per_iteration_us": 1e6 * run.planner_seconds / max(iterations * timed, 1.0),
        "time_per_period_us": 1e6 * run.planner_seconds / max(len(run.t) - 1, 1),
        "first_period_ms": 1e3 * run.first_period_seconds,
    } | extra


def max_speed_ratio(run: PlanResult, robot: RobotModel) -> float:
    """The largest |q̇_i| / (URDF speed limit of joint i) over the run, q̇ by finite
    differences of the periods (from q0 when known; a continuous joint the shortest way
    round); joints without a limit do not count.

    Args:
        run: the tracking run.
        robot: the robot, for its joint speed limits.

    Returns:
        The largest speed ratio (above 1: a limit is broken); 0 for fewer than two samples.
    """
    q = run.q if run.q0 is None else np.vstack([run.q0, run.q])
    if len(q) < 2 or len(run.t) < 2:
        return 0.0
    speed = np.abs(robot.difference(q[1:], q[:-1])) / (run.t[1] - run.t[0])
    limit = np.where(robot.velocity_limit > 0, robot.velocity_limit, np.inf)
    return float(np.max(speed / limit))


def max_acceleration_ratio(run: PlanResult, robot: RobotModel) -> float:
    """The largest |q̈_i| / (acceleration limit of joint i) over the run, q̈ by second
    differences of the periods from rest at q0 (when known; a continuous joint the shortest
    way round); joints without a limit do not count.

    Args:
        run: the tracking run.
        robot: the robot, for its joint acceleration limits.

    Returns:
        The largest acceleration ratio (above 1: a limit is broken); 0 for fewer than three
        samples.
    """
    return _max_rate_ratio(run, robot, 2, robot.acceleration_limit)


def max_jerk_ratio(run: PlanResult, robot: RobotModel) -> float:
    """The largest |d³q/dt³_i| / (jerk limit of joint i) over the run, by third differences
    of the periods from rest at q0 (as max_acceleration_ratio).

    Args:
        run: the tracking run.
        robot: the robot, for its joint jerk limits.

    Returns:
        The largest jerk ratio (above 1: a limit is broken); 0 for fewer than four samples.
    """
    return _max_rate_ratio(run, robot, 3, robot.jerk_limit)


def acceleration_use(run: PlanResult, robot: RobotModel, settled: np.ndarray) -> dict[str, float]:
    """How hard the commands use the acceleration limits once settled: accel_rms_ratio, the
    RMS over the settled periods and joints of |q̈_i| / (acceleration limit of joint i), and
    saturated_fraction, the share of settled periods with some joint at ≥ SATURATED of its
    limit; q̈ by second differences of the periods from rest at q0 (as
    max_acceleration_ratio), joints without a limit not counted.

    Args:
        run: the tracking run.
        robot: the robot, for its joint acceleration limits.
        settled: which periods count, shape (k,).

    Returns:
        accel_rms_ratio and saturated_fraction (0 for no settled period or no limit).
    """
    q = run.q if run.q0 is None else np.vstack([run.q0, run.q0, run.q])
    limit = robot.acceleration_limit
    counted = np.isfinite(limit) & (limit > 0)
    if len(run.t) < 2 or len(q) < 3 or not np.any(counted):
        return {"accel_rms_ratio": 0.0, "saturated_fraction": 0.0}
    motion = robot.difference(q[1:], q[:-1])
    ratio = np.abs(np.diff(motion, axis=0))[-len(run.t) :, counted] / (
        (run.t[1] - run.t[0]) ** 2 * limit[counted]
    )
    ratio = ratio[settled[-len(ratio) :]]
    if not ratio.size:
        return {"accel_rms_ratio": 0.0, "saturated_fraction": 0.0}
    return {
        "accel_rms_ratio": float(np.sqrt(np.mean(ratio**2))),
        "saturated_fraction": float(np.mean(np.any(ratio >= SATURATED, axis=1))),
    }


def _max_rate_ratio(run: PlanResult, robot: RobotModel, order: int, limit: np.ndarray) -> float:
    """The largest |order-th difference| / dt^order over `limit`, from rest at q0."""
    q = run.q if run.q0 is None else np.vstack([*[run.q0] * order, run.q])  # at rest before
    if len(q) < order + 1 or len(run.t) < 2:
        return 0.0
    motion = robot.difference(q[1:], q[:-1])
    rate = np.abs(np.diff(motion, order - 1, axis=0)) / (run.t[1] - run.t[0]) ** order
    return float(np.max(rate / limit))


def trace_columns(run: PlanResult) -> dict[str, np.ndarray]:
    """The run as trace columns: t, phase ("approach" before the path starts, then "path"),
    q_1..q_m, x, y, z, x_ref, y_ref, z_ref, error, clearance (link-obstacle),
    self_clearance (with checked link pairs) and orientation_error [rad] for a pose or axis
    task.

    Args:
        run: the tracking run.

    Returns:
        Column name -> its values, shape (k,), in the units of PlanResult.
    """
    columns = {"t": run.t, "phase": np.where(run.t < run.path_start, "approach", "path")}
    columns.update({f"q_{j + 1}": run.q[:, j] for j in range(run.q.shape[1])})
    columns.update({"x": run.x[:, 0], "y": run.x[:, 1], "z": run.x[:, 2]})
    columns.update({"x_ref": run.x_ref[:, 0], "y_ref": run.x_ref[:, 1], "z_ref": run.x_ref[:, 2]})
    columns.update({"error": run.error, "clearance": run.clearance})
    if run.self_clearance is not None:
        columns["self_clearance"] = run.self_clearance
    if run.orientation_error is not None:
        columns["orientation_error"] = run.orientation_error
    return columns
