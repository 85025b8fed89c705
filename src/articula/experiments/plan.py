"""The planning experiment `baornn.plan`, and the one function that turns a plan config into a
ready scene, reference path and controller.

A plan config is a scene file ([robot], [[obstacles]]) with a [trajectory] and a [planner]
table, and optionally `experiment = "baornn.plan"` and a top-level `seed`. `articula plan
SCENE.toml` and `articula run CONFIG.toml` both run it through the shared runner, so a plan
folder's config.toml re-runs and sweeps like any other experiment's. `build_plan` is how every
entry (plan, run, live, view, the bench suite, the peers benchmark, the examples) assembles
one, so that all of them read a file alike and name its keys alike in their errors.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from articula.errors import ConfigError
from articula.limits import MAX_SERVO_SAMPLES
from articula.loops.online import OnlineController
from articula.loops.sampled_clearance import STREAM_TOLERANCE, clearance_failure, sampled_clearance
from articula.loops.servo import run_stream, ticks_per_period
from articula.loops.stall import not_tracked_cause, stall_metrics
from articula.loops.tracking import trace_columns, track, tracking_metrics
from articula.planning.approach import Approach, approach
from articula.planning.config import PlannerSpec, TrajectorySpec, make_planner, make_targets
from articula.planning.config_files import absolute_paths
from articula.planning.kept_limits import kept_limits
from articula.planning.planner import Planner
from articula.planning.reach import check_reach
from articula.planning.target_path import TargetPath
from articula.planning.task import Target
from articula.runs.folders import SERVO
from articula.runs.registry import Experiment, Progress, Result
from articula.runs.runner import named_by_file
from articula.scene.config import SceneSpec, build_scene
from articula.scene.scene import Scene
from articula.validation import (
    Seed,
    StrictModel,
    field_error,
    fields_as,
    load_toml,
    parse_model,
)

NAME = "baornn.plan"
# Library argument names -> where the user wrote them in a plan config.
_CONFIG_PATHS = {"q0": "robot.q0", "dt": "planner.dt", "duration": "planner.duration"}


class ServoSpec(StrictModel):
    """[servo]: stream the plan's set-points to a joint servo (loops/servo.py) into
    servo.parquet.

    Attributes:
        rate: the servo rate [Hz]: a whole number of ticks per control period (1000 for a
            Franka, 500 for a UR's servoJ).
        max_samples: most samples the stream may have (planner.duration / dt · ticks).
    """

    rate: Annotated[float, Field(gt=0, le=100_000, allow_inf_nan=False)]
    max_samples: Annotated[int, Field(ge=1, le=10**9)] = MAX_SERVO_SAMPLES


class PlantSpec(StrictModel):
    """[plant]: the arm the commands drive; "mujoco": the dynamics twin (sim/twin.py, the
    `sim` extra), fed the servo stream, its measured joints closing the loop.

    Attributes:
        type: "mujoco".
        stiffness: each servo's kp over its joint's effort limit [1/rad].
        damping: each servo's kv over its kp [s].
    """

    type: Literal["mujoco"]
    stiffness: Annotated[float, Field(gt=0, le=1e6, allow_inf_nan=False)] = 100.0
    damping: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.05


class PlanConfig(SceneSpec):
    """A scene with the path to track and the planner that tracks it.

    `seed` seeds the planner's randomness; when absent, `planner.seed` (the form of scene
    files), else 0. The validated config holds it once, at the top.

    Attributes:
        robot: the [robot] table: the URDF, its start configuration q0 and its options.
        obstacles: the [[obstacles]] tables, in file order.
        seed: seed of the planner's randomness; after validation never None (`planner.seed`
            or 0 when absent).
        trajectory: the [trajectory] table: the path to track (circle of Eq. 1.27,
            rectangle, waypoints or CSV) and optionally the tool's orientation or axis.
        planner: the [planner] table: the method, its parameters, the control period and
            the run's duration.
        servo: the [servo] table: the servo stream to write (planner.limits then defaults
            to "velocity+acceleration+jerk", the only one it takes); None: none.
        plant: the [plant] table: the dynamics twin the stream drives (needs [servo]); None:
            the arm is where it was told.
    """

    seed: Seed | None = None
    trajectory: TrajectorySpec
    planner: PlannerSpec = PlannerSpec()
    servo: ServoSpec | None = None
    plant: PlantSpec | None = None

    @model_validator(mode="after")
    def _one_seed(self) -> PlanConfig:
        seed = self.seed if self.seed is not None else self.planner.seed
        object.__setattr__(self, "seed", 0 if seed is None else seed)
        object.__setattr__(self, "planner", self.planner.model_copy(update={"seed": None}))
        if self.plant is not None and self.servo is None:
            raise field_error(
                "servo", "a [plant] is driven by the servo stream: add [servo] rate = 1000"
            )
        if self.servo is not None:
            try:
                ticks = ticks_per_period(self.servo.rate, self.planner.dt)
            except ConfigError as exc:
                raise field_error(exc.field, exc.problem) from None
            samples = self.planner.duration / self.planner.dt * ticks
            if samples > self.servo.max_samples:
                raise field_error(
                    "servo.rate",
                    f"{self.planner.duration:g} s at {self.servo.rate:g} Hz is {samples:.3g} "
                    f"samples, more than servo.max_samples = {self.servo.max_samples}; lower "
                    "the rate, shorten planner.duration or raise servo.max_samples",
                )
            if "limits" not in self.planner.model_fields_set:  # a stream keeps the jerk limits
                limits = {"limits": "velocity+acceleration+jerk"}
                object.__setattr__(self, "planner", self.planner.model_copy(update=limits))
            if self.planner.limits != "velocity+acceleration+jerk":
                raise field_error(
                    "planner.limits",
                    f'planner.limits = "{self.planner.limits}": a servo stream needs set-points '
                    'within the jerk limits; set planner.limits = "velocity+acceleration+jerk"',
                )
        return self


@dataclass(frozen=True)
class PlanSetup:
    """A plan config made ready: its scene, start, path and planner settings.

    Attributes:
        config: the validated config.
        scene: the robot, its obstacles and its checked link pairs.
        q0: the start, shape (n,) [rad], continuous joints wrapped to (−π, π].
        targets: the path's targets over its own time [s].
        reference: the targets over the run's time: the approach from the tool at q0 to the
            path's start (`planner.approach = "auto"`), then the path.
        where: the config's file (or a name for it), which errors name.
    """

    config: PlanConfig
    scene: Scene
    q0: np.ndarray
    targets: TargetPath
    reference: Approach
    where: str

    @property
    def spec(self) -> PlannerSpec:
        """The [planner] table."""
        return self.config.planner

    def planner(self, method: str | None = None) -> Planner:
        """The config's planner (or `method` with the config's other settings).

        Args:
            method: a method name to use instead of `planner.method`; None: the config's.

        Returns:
            The planner, seeded with the config's seed.
        """
        spec = self.spec if method is None else _with_method(self.spec, method, self.where)
        with named_by_file(self.where), fields_as(_CONFIG_PATHS):
            return make_planner(spec, self.scene, self.config.seed)

    def controller(
        self, method: str | None = None, live_obstacles: bool = False
    ) -> OnlineController:
        """An online controller of the config's planner, reset at q0 (kernels compiled).

        Args:
            method: a method name to use instead of `planner.method`; None: the config's.
            live_obstacles: let step() move every obstacle of the scene.

        Returns:
            The controller, ready for its first step().
        """
        spec = self.spec if method is None else _with_method(self.spec, method, self.where)
        with named_by_file(self.where), fields_as(_CONFIG_PATHS):
            controller = OnlineController.from_spec(
                self.scene, spec, self.config.seed, live_obstacles=live_obstacles
            )
            controller.reset(self.q0)
        return controller


def build_plan(
    config: PlanConfig | Mapping[str, Any], base_dir: Path, where: str = ""
) -> PlanSetup:
    """The one assembly of a plan config: validated (errors name `where` and the TOML key),
    its scene, start, targets and reference with the approach.

    Args:
        config: the validated config, or its tables as read from TOML.
        base_dir: folder relative paths are taken from (the config file's).
        where: the config's file, prefixed to the key in errors.

    Returns:
        The plan, ready to plan or to run online.
    """
    if not isinstance(config, PlanConfig):
        body = {k: v for k, v in config.items() if k != "experiment"}
        config = parse_model(PlanConfig, body, where)
    p = config.planner
    with named_by_file(where):
        scene, q0 = build_scene(config, base_dir)
        targets = make_targets(config.trajectory, base_dir)
    # Every entry (the planner, the stream, the twin, live's arm) starts from this one pose: a
    # continuous joint written 4.80 rad starts at −1.48, as the controller reads it.
    q0 = scene.robot.wrap(q0)
    pose = scene.robot.ee_pose(q0)
    axis = pose[:3, :3] @ np.asarray(p.tool_axis, dtype=float)
    tool = Target(pose[:3, 3].copy(), pose[:3, :3].copy(), axis / np.linalg.norm(axis))
    if p.approach == "auto":
        reference = approach(targets, tool, p.approach_speed, p.approach_turn_rate)
    else:
        reference = Approach(targets, tool, 0.0)  # the path at once, as in the book
    return PlanSetup(config, scene, q0, targets, reference, where)


def run_plan(config: PlanConfig, progress: Progress | None = None) -> Result:
    """Track the path; metrics of loops.tracking.tracking_metrics and its trace columns.

    Relative file paths start at the working folder (a config read from a file has them made
    absolute by `absolute_paths`).

    Args:
        config: the validated plan config.
        progress: called as progress(done, total) every hundredth of the run; None: silent.

    Returns:
        The metrics of tracking_metrics (rms_error and max_error after `planner.settle` into
            the path [m], clearances [m], collisions, limits, planner timings) and of
            loops.stall.stall_metrics (stalled_s [s], the stall's pair and clearance [m]),
            `tracked` (False when rms_error after `planner.settle` exceeds
            `planner.tolerance`, max_error `planner.max_error_tolerance`, or, for a pose or
            axis task, rms_orientation_error `planner.orientation_tolerance`: the record's
            `not_tracked` then says why, with the cause measured); with [servo], run_stream's
            metrics and the stream's clearances at every sample (stream_min_clearance, ... of
            loops.sampled_clearance), `tracked` False when they fall below a floor by more
            than STREAM_TOLERANCE; with [plant], TwinArm.metrics (plant_rms_error, ...,
            torque_saturated_s), `tracked` False on TwinArm.failure; and the trace columns of
            trace_columns (t [s], phase, q_1..q_m [rad], x, y, z, their references x_ref,
            y_ref, z_ref, error and clearance [m]).

    Raises:
        InfeasibleError: the path is out of the robot's reach.
    """
    plan = build_plan(config, Path.cwd())
    p, lead = config.planner, plan.reference.duration
    with fields_as(_CONFIG_PATHS):
        check_reach(plan.scene.robot, plan.targets.positions, p.duration)
        planner = make_planner(p, plan.scene, config.seed)
        arm = None if config.plant is None else twin_arm(config, plan.scene, plan.q0)
        run = track(
            planner,
            plan.reference,
            plan.q0,
            p.dt,
            lead + p.duration,
            p.max_steps,
            progress,
            lead,
            arm,
        )
    metrics = tracking_metrics(
        run, plan.scene.robot, p.settle or 0.0, planner.iterations, plan.targets.cone
    )
    metrics |= stall_metrics(run, plan.scene, p.tolerance, p.d_min)
    why = _not_tracked(metrics, p, lead, len(run.t))
    trace, tables, floors = trace_columns(run), {}, (p.d_min, plan.scene.self_d_min)
    if config.servo is not None:
        stream, servo = run_stream(run, plan.scene.robot, config.servo.rate)
        metrics |= servo | sampled_clearance(plan.scene, stream.q, stream.t, "stream")
        tables = {SERVO: stream.columns()}
        why = why or clearance_failure(
            metrics, "stream", "the servo stream", floors, STREAM_TOLERANCE
        )
    if arm is not None:
        arm.brake()  # the stream's tail, as sent to the arm
        metrics |= arm.metrics(run, plan.scene, p.settle or 0.0)
        trace |= arm.columns()
        why = why or arm.failure(metrics, p.tolerance, floors)
    metrics["tracked"] = why is None
    details = {"limits": kept_limits(p, plan.scene.robot)}
    details |= {} if why is None else {"not_tracked": why}
    return Result(metrics, trace, tables=tables, details=details)


def _not_tracked(metrics: dict[str, Any], p: PlannerSpec, lead: float, periods: int) -> str | None:
    """Why the run did not track (the error beyond planner.tolerance or its largest beyond
    planner.max_error_tolerance, or the orientation's beyond planner.orientation_tolerance, and
    the cause measured), or None when it did."""
    after = f"{p.settle} s into the path" if lead else f"{p.settle} s"
    cause = not_tracked_cause(metrics, metrics["infeasible_steps"], periods)
    rms, most = metrics["rms_error"], metrics["max_error"]
    if rms > p.tolerance:
        return (
            f"not tracked: rms error {rms:.3g} m after {after} (max {most:.3g} m) exceeds "
            f"planner.tolerance = {p.tolerance} m: {cause}"
        )
    if most > p.max_error_tolerance:
        return (
            f"not tracked: max error {most:.3g} m after {after} (rms {rms:.3g} m) exceeds "
            f"planner.max_error_tolerance = {p.max_error_tolerance} m: {cause}"
        )
    turned = metrics.get("rms_orientation_error")
    if turned is not None and turned > p.orientation_tolerance:
        return (
            f"not tracked: rms orientation error {turned:.3g} rad after {after} (max "
            f"{metrics['max_orientation_error']:.3g} rad) exceeds planner.orientation_tolerance "
            f"= {p.orientation_tolerance} rad: {cause}"
        )
    return None


def twin_arm(config: PlanConfig, scene: Scene, q0: np.ndarray) -> Any:
    """The config's [plant]: the MuJoCo twin driven by its servo stream (sim.twin_arm).

    Args:
        config: the validated plan config, with [plant] and [servo].
        scene: the robot and obstacles the twin is built from.
        q0: where the arm starts, at rest, shape (n,) [rad].

    Returns:
        The arm (sim.twin_arm.TwinArm): command (n,) [rad] -> measured joints (n,) [rad].
    """
    try:  # the `sim` extra: imported only when asked for
        from articula.sim.twin import ServoGains
        from articula.sim.twin_arm import TwinArm
    except ImportError as exc:
        raise ConfigError(
            "plant.type",
            f'the MuJoCo twin needs the sim extra: pip install "articula[sim]" ({exc})',
        ) from None

    gains = ServoGains(config.plant.stiffness, config.plant.damping)
    return TwinArm(scene, q0, config.planner.dt, config.servo.rate, gains)


def load_plan(path: Path, servo_rate: float | None = None) -> dict[str, Any]:
    """A scene file (or a plan folder's config.toml) as a `baornn.plan` config, its file paths
    made absolute.

    Args:
        path: the scene file or config.toml; its relative paths start at its folder.
        servo_rate: a servo rate [Hz] that replaces the file's servo.rate; None: the file's.

    Returns:
        The config's tables as read from TOML, `experiment` set to "baornn.plan" when absent
            and its URDF, package folders, meshes and trajectory CSV paths made absolute.

    Raises:
        ConfigError: the file names another experiment (run it with `articula run`).
    """
    data = load_toml(path)
    name = data.setdefault("experiment", NAME)
    if name != NAME:
        raise ConfigError(
            f"{path}: experiment",
            f"plan runs {NAME} configs (got {name!r}); run this file with `articula run`",
        )
    if servo_rate is not None:
        data["servo"] = {**data.get("servo", {}), "rate": servo_rate}
    return absolute_paths(data, path.parent)


def _with_method(spec: PlannerSpec, method: str, where: str) -> PlannerSpec:
    """spec with another method, checked as the file's planner.method would be."""
    return parse_model(PlannerSpec, {**spec.model_dump(), "method": method}, where or "planner")


PLAN = Experiment(NAME, PlanConfig, run_plan, absolute_paths)
