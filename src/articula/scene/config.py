"""Scene files: the [robot] and [[obstacles]] tables of a TOML file, validated."""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Annotated, Any

import numpy as np
from pydantic import Field, model_validator

from articula.errors import ConfigError, GeometryError
from articula.geometry.meshes import convex_parts, load_mesh
from articula.geometry.poses import pose
from articula.geometry.shapes import ConvexShape, box, capsule, cylinder, sphere
from articula.limits import MAX_DECOMPOSE_VERTICES, MAX_LENGTH, MAX_LINKS, MAX_SCALE, MIN_SCALE
from articula.robots.datasheets import Datasheet, apply_datasheet
from articula.robots.limits import ACCEL_TIME, JERK_TIME, USER, published_or_rule
from articula.robots.model import RobotModel
from articula.scene.obstacles import Obstacle
from articula.scene.pairs import link_pairs
from articula.scene.scene import SELF_D_MIN, Metric, Scene
from articula.scene.self_collision import (
    MARGIN,
    SAMPLES,
    SelfCollisionMatrix,
    self_collision_matrix,
)
from articula.validation import (
    Point,
    Positive,
    PositiveLength,
    Radians,
    StrictModel,
    fields_as,
    parse_model,
)

Scale = Annotated[float, Field(ge=MIN_SCALE, le=MAX_SCALE, allow_inf_nan=False)]
Rpy = Annotated[list[Radians], Field(min_length=3, max_length=3)]
Sizes3 = Annotated[list[PositiveLength], Field(min_length=3, max_length=3)]
Sizes2 = Annotated[list[PositiveLength], Field(min_length=2, max_length=2)]
SHAPE_KEYS = ("mesh", "box", "sphere", "cylinder", "capsule")
PACKAGE_URI = "package://articula/"  # a file shipped inside articula


class EeOffsetSpec(StrictModel):
    """[robot] ee_offset: the tool point's pose in the ee_frame, xyz [m] and rpy [rad].

    Attributes:
        xyz: position of the tool point in the ee_frame, shape (3,) [m].
        rpy: roll, pitch, yaw of the tool frame in the ee_frame, shape (3,) [rad].
    """

    xyz: Point = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: Rpy = Field(default_factory=lambda: [0.0, 0.0, 0.0])


class RobotSpec(StrictModel):
    """[robot]: a built-in robot or a URDF, and its initial configuration q0 [rad]; joints to
    lock at fixed values [rad or m] and the tool point's offset from ee_frame.

    Attributes:
        builtin: name of a robot shipped with articula ("iiwa14", "ur5e"); give this or `urdf`.
        urdf: path of the URDF file (relative to the scene file, or package://articula/...).
        package_dirs: folders that hold the packages the URDF's package:// meshes name.
        ee_frame: the end-effector frame; default the built-in robot's, or the last link.
        ee_offset: pose of the tool point in the ee_frame, which then becomes the end effector.
        locked_joints: joint name -> fixed value [rad or m]; these joints leave the model.
        q0: initial joint positions, one per joint [rad]; default all zero.
        max_links: largest URDF accepted, in links.
        decompose: link meshes CoACD decomposes into convex parts: true for all, or link names.
        self_collision: whether link-link distances are checked: every planner keeps the
            links of a checked pair self_d_min apart, and a step closer than 0 is a collision.
        self_d_min: clearance every planner keeps between the links of a checked pair [m].
        datasheet: the arm's published limits (robots.datasheets: "franka-panda",
            "franka-fr3", "ur3e", "ur5e", "ur10e", "ur16e", "ur5", "ur10", "kinova-gen3");
            each position, speed and effort limit is the tighter of the datasheet's and the
            URDF's, acceleration and jerk the datasheet's where it publishes them. None: the
            datasheet the URDF's joint names identify (panda_joint1..7: franka-panda,
            fr3_joint1..7: franka-fr3), else none; "none": no datasheet.
        acceleration_limits: joint acceleration limits, one for every joint or one per joint
            [rad/s² or m/s²]; None: the datasheet's, else each joint's speed limit over
            accel_time.
        accel_time: time from rest to a joint's speed limit where neither acceleration_limits
            nor the datasheet gives an acceleration limit [s].
        jerk_limits: joint jerk limits, one for every joint or one per joint [rad/s³ or
            m/s³]; None: the datasheet's, else each acceleration limit over jerk_time.
        jerk_time: time from zero to a joint's acceleration limit where neither jerk_limits
            nor the datasheet gives a jerk limit [s].
        allow_pairs: [a, b] link name pairs never checked for self-collision.
        self_collision_samples: random configurations the allowed-collision matrix is built on.
        self_collision_margin: a link pair never closer than this over the samples is not
            checked [m].
    """

    builtin: str | None = None
    urdf: str | None = None
    package_dirs: list[str] = Field(default_factory=list)
    ee_frame: str | None = None
    ee_offset: EeOffsetSpec | None = None
    locked_joints: dict[str, Radians] = Field(default_factory=dict)
    q0: list[Radians] | None = None
    max_links: Annotated[int, Field(ge=1, le=100_000)] = MAX_LINKS
    # Link meshes CoACD decomposes (true: all; or link names) instead of one hull per part:
    # a non-convex link keeps its concavities, so clearance is not under-stated there.
    decompose: bool | list[str] = False
    # Link-link distances are kept above self_d_min, for the pairs of scene/self_collision.py's
    # allowed-collision matrix; allow_pairs are never checked.
    self_collision: bool = True
    self_d_min: Annotated[float, Field(ge=0, le=MAX_LENGTH, allow_inf_nan=False)] = SELF_D_MIN
    datasheet: str | None = None
    acceleration_limits: Positive | list[Positive] | None = None
    accel_time: Positive = ACCEL_TIME
    jerk_limits: Positive | list[Positive] | None = None
    jerk_time: Positive = JERK_TIME
    allow_pairs: list[Annotated[list[str], Field(min_length=2, max_length=2)]] = Field(
        default_factory=list
    )
    self_collision_samples: Annotated[int, Field(ge=1, le=100_000)] = SAMPLES
    self_collision_margin: Annotated[float, Field(ge=0, le=MAX_LENGTH, allow_inf_nan=False)] = (
        MARGIN  # [m]
    )

    @model_validator(mode="after")
    def _one_source(self) -> RobotSpec:
        if (self.builtin is None) == (self.urdf is None):
            raise ValueError('give exactly one of builtin = "iiwa14" or urdf = "path"')
        return self


class ObstacleSpec(StrictModel):
    """[[obstacles]]: one shape (mesh file or primitive) with a pose; sizes in m.

    Attributes:
        name: the obstacle's name; default obstacle_<index>.
        mesh: path of a mesh file (STL, OBJ, PLY, DAE), relative to the scene file.
        scale: factor from the mesh file's units to metres, one or per axis (x, y, z).
        decompose: whether CoACD decomposes the mesh into convex parts instead of one hull.
        max_vertices: largest mesh, in vertices, a decomposition accepts.
        box: edge lengths along x, y, z [m].
        sphere: radius [m].
        cylinder: radius and length along z [m].
        capsule: radius and length along z between the caps' centres [m].
        position: position of the obstacle frame in the world, shape (3,) [m].
        rpy: roll, pitch, yaw of the obstacle frame in the world, shape (3,) [rad].
        velocity: constant velocity of the obstacle from its position at t = 0, shape (3,)
            [m/s]; None for a still obstacle.
    """

    name: str | None = None
    mesh: str | None = None
    scale: Scale | Annotated[list[Scale], Field(min_length=3, max_length=3)] = 1.0
    decompose: bool = False
    max_vertices: Annotated[int, Field(ge=1, le=100_000_000)] = MAX_DECOMPOSE_VERTICES
    box: Sizes3 | None = None
    sphere: PositiveLength | None = None
    cylinder: Sizes2 | None = None
    capsule: Sizes2 | None = None
    position: Point = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: Rpy = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    velocity: Point | None = None

    @model_validator(mode="after")
    def _one_shape(self) -> ObstacleSpec:
        given = [k for k in SHAPE_KEYS if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of {', '.join(SHAPE_KEYS)} (got {given or 'none'})")
        if self.mesh is None and (self.decompose or self.scale != 1.0):
            raise ValueError("scale and decompose apply to mesh obstacles only")
        return self


class SceneSpec(StrictModel):
    """A whole scene file.

    Attributes:
        robot: the [robot] table.
        obstacles: the [[obstacles]] tables, in file order.
    """

    robot: RobotSpec
    obstacles: list[ObstacleSpec] = Field(default_factory=list)


def load_scene_spec(data: dict[str, Any], where: str = "") -> SceneSpec:
    """Validate the [robot] and [[obstacles]] tables of a mapping (other keys are ignored).

    Args:
        data: the parsed TOML file.
        where: the file's name, prefixed to the field in errors.

    Returns:
        The validated scene.
    """
    body = {k: data[k] for k in ("robot", "obstacles") if k in data}
    if "robot" not in body:
        raise ConfigError(f"{where}: robot" if where else "robot", "the [robot] table is missing")
    return parse_model(SceneSpec, body, where)


def build_scene(
    spec: SceneSpec, base_dir: Path, broadphase: bool = True, metric: Metric = "gjk"
) -> tuple[Scene, np.ndarray]:
    """The Scene and its initial configuration q0; relative paths start at `base_dir`.

    Args:
        spec: the validated scene file.
        base_dir: folder relative paths are taken from (the scene file's).
        broadphase: whether distance queries skip pairs by their bounding capsules.
        metric: "gjk" (exact convex distance) or "vertex" (the book's Sect. 1.3.3 formula).

    Returns:
        The scene and q0, the initial joint positions, shape (nq,) [rad].
    """
    r = spec.robot
    fields = {name: f"robot.{name}" for name in RobotSpec.model_fields}
    fields |= {f"locked_joints.{name}": f"robot.locked_joints.{name}" for name in r.locked_joints}
    offset = None if r.ee_offset is None else pose(r.ee_offset.xyz, r.ee_offset.rpy)
    with fields_as(fields):
        if r.builtin is not None:
            robot = RobotModel.builtin(
                r.builtin, r.ee_frame, r.locked_joints, offset, decompose=r.decompose
            )
        else:
            robot = RobotModel.from_urdf(
                resolve_path(base_dir, r.urdf or ""),
                [resolve_path(base_dir, d) for d in r.package_dirs],
                r.ee_frame,
                r.max_links,
                r.locked_joints,
                offset,
                decompose=r.decompose,
            )
        sheet = apply_datasheet(robot, r.datasheet)
        robot.acceleration_limit, robot.limit_sources["acceleration"] = _limit(
            r.acceleration_limits, sheet, robot.velocity_limit, r.accel_time, _ACCELERATION
        )
        robot.jerk_limit, robot.limit_sources["jerk"] = _limit(
            r.jerk_limits, sheet, robot.acceleration_limit, r.jerk_time, _JERK
        )
    q0 = robot.check_q(r.q0 if r.q0 is not None else np.zeros(robot.nq), "robot.q0")
    obstacles = []
    for i, o in enumerate(spec.obstacles):
        try:
            obstacles.append(_obstacle(o, i, base_dir))
        except GeometryError as exc:
            raise ConfigError(f"obstacles[{i}] ({o.name or f'obstacle_{i}'})", str(exc)) from None
    names = [link.name for link in robot.links]
    link_pairs(r.allow_pairs, names, "robot.allow_pairs")  # a typo is an error even when off
    self_pairs = robot_self_collision(spec, robot).checked if r.self_collision else ()
    return Scene(robot, obstacles, broadphase, metric, self_pairs, r.self_d_min), q0


def robot_self_collision(spec: SceneSpec, robot: RobotModel) -> SelfCollisionMatrix:
    """The allowed-collision matrix a scene file's [robot] table asks for (whether or not
    self_collision is on); errors name the [robot] key.

    Args:
        spec: the validated scene file.
        robot: the robot built from its [robot] table.

    Returns:
        The link pairs to check and the skipped ones.
    """
    r = spec.robot
    with fields_as({"allow_pairs": "robot.allow_pairs"}):
        return self_collision_matrix(
            robot, r.allow_pairs, r.self_collision_samples, r.self_collision_margin
        )


# A limit's datasheet attribute, its [robot] key, the key of its rise time, and its unit.
_ACCELERATION = ("acceleration", "acceleration_limits", "accel_time", "rad/s²")
_JERK = ("jerk", "jerk_limits", "jerk_time", "rad/s³")


def _limit(
    stated: float | list[float] | None,
    sheet: Datasheet | None,
    below: np.ndarray,
    rise_time: float,
    keys: tuple[str, str, str, str],
) -> tuple[np.ndarray, tuple[str, ...]]:
    """A [robot] limit per joint and its sources: the stated one (one number or one per
    joint), else the datasheet's where it publishes one, else the limit `below` reached from
    zero in rise_time (robots.limits.published_or_rule)."""
    attribute, key, time_key, unit = keys
    if stated is None:
        if sheet is None:
            return published_or_rule(None, below, rise_time, time_key, None)
        return published_or_rule(getattr(sheet, attribute), below, rise_time, time_key, sheet.name)
    limits = np.asarray(stated, dtype=float)
    if limits.ndim == 0:
        return np.full(below.size, float(limits)), (USER,) * below.size
    if limits.shape != below.shape:
        raise ConfigError(
            key, f"needs one number or {below.size}, one per joint [{unit}] (got {limits.size})"
        )
    return limits, (USER,) * below.size


def _obstacle(spec: ObstacleSpec, index: int, base_dir: Path) -> Obstacle:
    name = spec.name or f"obstacle_{index}"
    parts: list[ConvexShape]
    if spec.mesh is not None:
        mesh_path = resolve_path(base_dir, spec.mesh)
        scale = tuple(spec.scale) if isinstance(spec.scale, list) else spec.scale
        mesh = load_mesh(mesh_path, scale)
        parts = convex_parts(mesh, name, spec.decompose, max_vertices=spec.max_vertices)
    else:
        parts = [_primitive(spec)]
    start = pose(spec.position, spec.rpy)
    if spec.velocity is None:
        return Obstacle(name, tuple(parts), start)
    velocity = np.asarray(spec.velocity)

    def moving(t: float) -> np.ndarray:
        T = start.copy()
        T[:3, 3] += velocity * t
        return T

    return Obstacle(name, tuple(parts), moving)


def _primitive(spec: ObstacleSpec) -> ConvexShape:
    """The one primitive an ObstacleSpec names (its validator guarantees exactly one)."""
    if spec.box is not None:
        return box((spec.box[0], spec.box[1], spec.box[2]))
    if spec.sphere is not None:
        return sphere(spec.sphere)
    if spec.cylinder is not None:
        return cylinder(*spec.cylinder)
    radius, length = spec.capsule or (0.0, 0.0)
    return capsule(radius, length)


def resolve_path(base_dir: Path, text: str) -> Path:
    """A path from a scene file: `package://articula/...` inside the installed package (the
    same config then finds its files on any machine), `~` expanded, relative ones taken from
    `base_dir`.

    Args:
        base_dir: folder relative paths are taken from (the scene file's).
        text: the path as written in the file.

    Returns:
        The path (not checked to exist).
    """
    if text.startswith(PACKAGE_URI):
        return Path(str(resources.files("articula").joinpath(text.removeprefix(PACKAGE_URI))))
    path = Path(text).expanduser()
    return path if path.is_absolute() else base_dir / path
