"""The [trajectory] and [planner] tables of a scene file, validated, and what they build."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal, get_args

import numpy as np
from pydantic import Field, model_validator

from articula.limits import MAX_STEPS
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.baornn_improved import ImprovedBaornn, ImprovedParams
from articula.planning.objective import Objective
from articula.planning.planner import Planner
from articula.planning.qp_ik import QpIk, QpIkParams
from articula.planning.rate_limits import RateLimits
from articula.planning.target_path import (
    TargetPath,
    WaypointRotations,
    axis_direction,
    csv_rotations,
    fixed_rotation,
    rotation_from,
)
from articula.planning.task import Task, TaskKind
from articula.planning.trajectories import Circle, Waypoints, rectangle
from articula.planning.velocity_ik import VelocityIk, VelocityIkParams
from articula.robots.model import RobotModel
from articula.scene.config import resolve_path
from articula.scene.scene import Scene
from articula.validation import (
    Finite,
    NonNegative,
    Point,
    Positive,
    PositiveLength,
    Radians,
    Seed,
    StrictModel,
    field_error,
    fields_as,
)

Method = Literal["baornn", "baornn-improved", "pinv", "dls", "qp"]
METHODS: tuple[str, ...] = get_args(Method)  # every planning method, by its [planner] name
Limits = Literal["velocity+acceleration+jerk", "velocity+acceleration", "velocity", "none"]
Rpy = Annotated[list[Radians], Field(min_length=3, max_length=3)]
Quaternion = Annotated[list[Finite], Field(min_length=4, max_length=4)]


class TrajectorySpec(StrictModel):
    """[trajectory]: circle (Eq. 1.27), rectangle, waypoints or csv.

    Attributes:
        type: the path's kind: "circle", "rectangle", "waypoints" or "csv".
        center: centre C of the circle, shape (3,) [m].
        axis_a: first in-plane unit axis A of the circle, shape (3,).
        axis_b: second in-plane unit axis B of the circle, perpendicular to A, shape (3,).
        radius: radius r of the circle [m].
        period: time T of one lap (circle, rectangle) [s].
        vertices: the rectangle's four corners, shape (4, 3) [m].
        points: the waypoints, at least two, shape (k, 3) [m].
        times: when each waypoint is reached, increasing, shape (k,) [s].
        path: CSV file of t, x, y, z rows (and optionally an orientation), relative to the
            scene file.
        rpy: fixed tool orientation as roll, pitch, yaw about the world's x, y, z [rad].
        quaternion: fixed tool orientation as a quaternion [w, x, y, z].
        rpys: one roll, pitch, yaw per waypoint, interpolated by slerp [rad].
        quaternions: one quaternion [w, x, y, z] per waypoint, interpolated by slerp.
        axis: world direction the tool axis should point along (position+axis task), (3,).
        cone: how far the tool axis may be from `axis`, in (0, π] [rad].
    """

    type: Literal["circle", "rectangle", "waypoints", "csv"]
    center: Point | None = None
    axis_a: Point | None = None
    axis_b: Point | None = None
    radius: PositiveLength | None = None
    period: Positive | None = None
    vertices: list[Point] | None = None
    points: list[Point] | None = None
    times: list[Finite] | None = None
    path: str | None = None
    # The tool's orientation (pose task): fixed, or one per waypoint (interpolated by slerp).
    rpy: Rpy | None = None
    quaternion: Quaternion | None = None
    rpys: list[Rpy] | None = None
    quaternions: list[Quaternion] | None = None
    # The tool axis's direction (position+axis task) and how far from it it may be [rad].
    axis: Point | None = None
    cone: Annotated[float, Field(gt=0, le=np.pi, allow_inf_nan=False)] | None = None

    @model_validator(mode="after")
    def _fields_of_type(self) -> TrajectorySpec:
        needed = {
            "circle": ("center", "axis_a", "axis_b", "radius", "period"),
            "rectangle": ("vertices", "period"),
            "waypoints": ("points", "times"),
            "csv": ("path",),
        }[self.type]
        missing = [k for k in needed if getattr(self, k) is None]
        if missing:
            raise ValueError(f"type = {self.type!r} needs {', '.join(missing)}")
        given = [k for k in ("rpy", "quaternion", "rpys", "quaternions") if getattr(self, k)]
        if len(given) > 1:
            raise ValueError(f"give one orientation, not {' and '.join(given)}")
        if (self.rpys or self.quaternions) and self.type != "waypoints":
            raise ValueError("rpys and quaternions (one per point) need type = 'waypoints'")
        if self.cone is not None and self.axis is None:
            raise ValueError("cone needs an axis")
        return self


class PlannerSpec(StrictModel):
    """[planner]: the method and its parameters; keys a method does not use are ignored.

    Attributes:
        method: "baornn", "baornn-improved", or the baselines "pinv", "dls" and "qp".
        lambda_weight: penalty weight Λ of Eq. (1.11), BAORNN [m^(1+β)].
        beta: penalty exponent β of Eq. (1.11), BAORNN.
        d_min: hard clearance of Eq. (1.12) [m].
        dt: control period [s].
        iterations_per_step: BAORNN iterations per control period.
        duration: length of the run [s].
        settle: time before rms_error and max_error are measured; default min(5, T/2) [s].
        tolerance: rms_error above which the path counts as not tracked [m].
        max_error_tolerance: max_error above which the path counts as not tracked, however
            small the rms_error: a run stuck off the path for a while [m]; default twice
            `tolerance` (0.1 m: above every settled max_error of the five methods on the
            chapter-1 scenes and the tests' arms, at most 95 mm, and below the 117 mm of a
            UR10 stuck at a ball; docs/deviations.md).
        orientation_tolerance: rms_orientation_error above which a pose or axis task counts
            as not tracked [rad].
        c1: antenna length constant of Eq. (1.23), BAORNN [rad/√m].
        c2: step constant of Eq. (1.24), BAORNN.
        pairs: antenna pairs per iteration, baornn-improved.
        short_antenna: relative length of every second antenna pair, baornn-improved.
        yield_distance: clearance below which baornn-improved may leave the path to keep
            clear (above it the penalty uses the redundancy only; inf: the book's) [m].
        newton_damping: μ of baornn-improved's Gauss-Newton candidate; 0: none [m].
        quiet_error: task error below which a baornn-improved period stops iterating where
            the penalty is flat; 0: never early [m].
        flat_penalty_slope: the penalty slope Λβ/d^(β+1) below which baornn-improved tries
            the Gauss-Newton step and may stop early; 0: never [-].
        slide_reach: nearness to d_min or self_d_min where baornn-improved slides; 0: never [m].
        smoothing: "acceleration": BAORNN's period ends where g descends with the least
            acceleration (planning/smooth.py); "none": where the search left it (the book's).
        gain: K on the task error, baselines [1/s].
        damping: μ of damped least squares, dls [m].
        repulsion: η of the obstacle repulsion, pinv and dls [m²/s].
        influence: distance below which an obstacle counts, baselines [m].
        safety: distance d_s the qp's velocity dampers keep [m].
        seed: seed of the planner's randomness; also accepted at the top of a plan config,
            where it wins (see PlanConfig).
        max_steps: most control periods a run may have (duration / dt).
        limits: "velocity+acceleration": the robot's joint speed limits (scaled) and the
            robot's acceleration limits ([robot] acceleration_limits or accel_time), relative
            to the last period's motion; "velocity+acceleration+jerk": and the robot's jerk
            limits ([robot] jerk_limits or jerk_time), relative to the last two periods';
            "velocity": the speed limits alone; "none": BAORNN moves as fast as the book's
            Algorithm 1 (the baselines' solvers always keep the speed limits).
        velocity_scale: fraction of the robot's joint speed limits, in (0, 1].
        max_acceleration: one acceleration limit for every joint that overrides the robot's
            (limits with "acceleration" only); None: the robot's [rad/s²].
        approach: "auto": when the path starts away from the tool, the reference first moves
            from the tool to the path's start (the approach), then the path begins; "none":
            the path begins at once, as in the book.
        approach_speed: the approach's peak tool speed [m/s].
        approach_turn_rate: the approach's peak tool turn rate (pose and axis tasks) [rad/s].
        task: what the end effector tracks: "position", "pose" or "position+axis"; without
            an orientation or axis in the trajectory, the start's is held.
        orientation_weight: BAORNN's weight on the orientation error [m/rad].
        tool_axis: the tool axis in the end-effector frame, shape (3,).
    """

    method: Method = "baornn"
    lambda_weight: NonNegative = 0.0
    beta: NonNegative = 1.0
    d_min: NonNegative = 0.0
    dt: Positive = 0.01
    iterations_per_step: Annotated[int, Field(ge=1, le=10_000)] = 10
    duration: Positive = 50.0
    settle: NonNegative | None = None
    tolerance: Positive = 0.05
    max_error_tolerance: Positive | None = None
    orientation_tolerance: Annotated[float, Field(gt=0, le=np.pi, allow_inf_nan=False)] = 0.05
    c1: Positive = 0.5
    c2: Positive = 0.5
    pairs: Annotated[int, Field(ge=1, le=64)] = 3
    short_antenna: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.25
    yield_distance: Annotated[float, Field(ge=0)] = 0.03
    newton_damping: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.02
    quiet_error: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 1e-5
    flat_penalty_slope: Annotated[float, Field(ge=0)] = 0.1
    slide_reach: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.01
    smoothing: Literal["acceleration", "none"] = "acceleration"
    gain: NonNegative = 20.0
    damping: NonNegative = 0.02
    repulsion: NonNegative = 0.02
    influence: Positive = 0.15
    safety: NonNegative = 0.03
    seed: Seed | None = None
    max_steps: Annotated[int, Field(ge=1, le=10**9)] = MAX_STEPS
    limits: Limits = "velocity+acceleration"
    velocity_scale: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 1.0
    max_acceleration: Positive | None = None
    approach: Literal["auto", "none"] = "auto"
    approach_speed: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.25
    approach_turn_rate: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.5
    # What the end effector tracks beyond the book's position (none given: the start's held).
    task: TaskKind = "position"
    orientation_weight: NonNegative = 0.1
    tool_axis: Point = Field(default_factory=lambda: [0.0, 0.0, 1.0])

    @model_validator(mode="after")
    def _times(self) -> PlannerSpec:
        steps = self.duration / self.dt
        if steps > self.max_steps:
            raise field_error(
                "duration",
                f"{self.duration:g} s at dt = {self.dt:g} s is {steps:.3g} control periods, more "
                f"than max_steps = {self.max_steps}; shorten duration, raise dt or raise "
                "planner.max_steps",
            )
        if self.settle is None:
            object.__setattr__(self, "settle", min(5.0, self.duration / 2))
        if self.max_error_tolerance is None:
            object.__setattr__(self, "max_error_tolerance", 2 * self.tolerance)
        if self.settle >= self.duration:
            raise field_error("settle", f"must be shorter than duration = {self.duration} s")
        if self.max_acceleration is not None and "acceleration" not in self.limits:
            raise field_error(
                "max_acceleration",
                f"limits = {self.limits!r} keeps no acceleration limit; remove max_acceleration "
                'or set limits = "velocity+acceleration"',
            )
        return self


def make_planner(spec: PlannerSpec, scene: Scene, seed: int) -> Planner:
    """The planner a PlannerSpec names, on `scene`, its randomness drawn from `seed`.

    The method's own parameter model checks what only it needs (a QP's safety distance inside
    its influence distance); its errors name the [planner] key.

    Args:
        spec: the validated [planner] table.
        scene: the robot and obstacles to plan in.
        seed: seed of the planner's random generator.

    Returns:
        The planner, ready for its first control period.
    """
    with fields_as(PARAMETER_KEYS):
        return _planner(spec, scene, seed)


def _planner(spec: PlannerSpec, scene: Scene, seed: int) -> Planner:
    """make_planner without the renaming of its errors."""
    rng = np.random.default_rng(seed)
    task = Task(spec.task, spec.orientation_weight, np.asarray(spec.tool_axis))
    objective = Objective(scene, spec.lambda_weight, spec.beta, spec.d_min, task=task)
    rate = rate_limits(spec, scene.robot)
    if spec.method == "baornn":
        return Baornn(objective, _params(BaornnParams, spec), rng, rate)
    if spec.method == "baornn-improved":
        return ImprovedBaornn(objective, _params(ImprovedParams, spec), rng, rate)
    if spec.method == "qp":
        qp = _params(QpIkParams, spec, speed_scale=spec.velocity_scale)
        return QpIk(scene, spec.dt, qp, d_min=spec.d_min, task=task, rate=rate)
    velocity = _params(VelocityIkParams, spec, speed_scale=spec.velocity_scale)
    return VelocityIk(scene, spec.method, spec.dt, velocity, d_min=spec.d_min, task=task, rate=rate)


def _params(model: type[StrictModel], spec: PlannerSpec, **extra: Any) -> Any:
    """`model` from the [planner] keys named as its fields (the rest its defaults), and
    `extra`."""
    keys = {k: getattr(spec, k) for k in model.model_fields if k in PlannerSpec.model_fields}
    return model(**keys, **extra)


def rate_limits(spec: PlannerSpec, robot: RobotModel) -> RateLimits | None:
    """The joint speed limits of `robot` (URDF or datasheet, times velocity_scale; a joint without
    one has none) and, as spec.limits says, its acceleration (max_acceleration for every joint
    when given) and jerk limits, relative to the last periods' motions.

    Args:
        spec: the validated [planner] table.
        robot: the robot whose URDF velocity limits are scaled.

    Returns:
        The per-period limits, or None when spec.limits is "none" (the baselines then keep
        the speed limits alone).
    """
    if spec.limits == "none":
        return None
    speeds = np.where(robot.velocity_limit > 0, robot.velocity_limit, np.inf)
    acceleration = None
    if "acceleration" in spec.limits:
        acceleration = (
            robot.acceleration_limit if spec.max_acceleration is None else spec.max_acceleration
        )
    jerk = robot.jerk_limit if "jerk" in spec.limits else None
    return RateLimits(spec.velocity_scale * speeds, spec.dt, acceleration, jerk)


# "QpIkParams.safety" -> "planner.safety": the library's names of the [planner] keys.
PARAMETER_KEYS = (
    {
        f"{model.__name__}.{name}": f"planner.{name}"
        for model in (BaornnParams, ImprovedParams, QpIkParams, VelocityIkParams)
        for name in model.model_fields
    }
    | {f"Objective.{name}": f"planner.{name}" for name in ("lambda_weight", "beta", "d_min")}
    | {"orientation_weight": "planner.orientation_weight", "tool_axis": "planner.tool_axis"}
)


def make_trajectory(spec: TrajectorySpec, base_dir: Path) -> Circle | Waypoints:
    """The reference path a TrajectorySpec names; errors name the [trajectory] key at fault.

    Args:
        spec: the validated [trajectory] table.
        base_dir: folder a relative CSV path is resolved from.

    Returns:
        The position path x_r(t) [m].
    """
    with fields_as({name: f"trajectory.{name}" for name in TrajectorySpec.model_fields}):
        return _trajectory(spec, base_dir)


def make_targets(spec: TrajectorySpec, base_dir: Path) -> TargetPath:
    """The targets a TrajectorySpec names: its path, and its orientation and axis if given.

    Args:
        spec: the validated [trajectory] table.
        base_dir: folder a relative CSV path is resolved from.

    Returns:
        The target at each time: position, and orientation and tool axis if given.
    """
    with fields_as({name: f"trajectory.{name}" for name in TrajectorySpec.model_fields}):
        path = _trajectory(spec, base_dir)
        rotations = None
        if spec.rpy is not None or spec.quaternion is not None:
            rotations = fixed_rotation(rotation_from(spec.rpy, spec.quaternion))
        elif spec.rpys is not None or spec.quaternions is not None:
            each = [rotation_from(r, None) for r in spec.rpys or []] + [
                rotation_from(None, quaternion) for quaternion in spec.quaternions or []
            ]
            field = "rpys" if spec.rpys is not None else "quaternions"
            rotations = WaypointRotations.create(each, spec.times or [], field)
        if spec.type == "csv":
            rotations = csv_rotations(resolve_path(base_dir, spec.path or ""))
        axis = None if spec.axis is None else axis_direction(spec.axis)
        return TargetPath(path, rotations, axis, spec.cone)


def _trajectory(spec: TrajectorySpec, base_dir: Path) -> Circle | Waypoints:
    """make_trajectory without the renaming of its errors."""
    if spec.type == "circle":
        return Circle.create(
            spec.center or [],
            spec.axis_a or [],
            spec.axis_b or [],
            spec.radius or 0.0,
            spec.period or 0.0,
        )
    if spec.type == "rectangle":
        return rectangle(spec.vertices or [], spec.period or 0.0)
    if spec.type == "waypoints":
        return Waypoints.create(spec.points or [], spec.times or [])
    return Waypoints.from_csv(resolve_path(base_dir, spec.path or ""))
