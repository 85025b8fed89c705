"""`articula plan`: a scene file with [trajectory] and [planner] tables, tracked by BAORNN."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from articula.errors import ConfigError, InfeasibleError
from articula.experiments import records
from articula.experiments.registry import Result
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.baornn_improved import ImprovedBaornn, ImprovedParams
from articula.planning.objective import Objective
from articula.planning.planner import Planner
from articula.planning.qp_ik import QpIk, QpIkParams
from articula.planning.reach import check_reach
from articula.planning.track import PlanResult, track
from articula.planning.trajectories import Circle, Waypoints, rectangle
from articula.planning.velocity_ik import VelocityIk, VelocityIkParams
from articula.scene.config import build_scene, load_scene_spec, resolve_path
from articula.scene.scene import Scene
from articula.validation import StrictModel, field_error, load_toml, parse_model

Finite = Annotated[float, Field(allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]


class TrajectorySpec(StrictModel):
    """[trajectory]: circle (Eq. 1.27), rectangle, waypoints or csv."""

    type: Literal["circle", "rectangle", "waypoints", "csv"]
    center: Vec3 | None = None
    axis_a: Vec3 | None = None
    axis_b: Vec3 | None = None
    radius: Positive | None = None
    period: Positive | None = None
    vertices: list[Vec3] | None = None
    points: list[Vec3] | None = None
    times: list[Finite] | None = None
    path: str | None = None

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
        return self


Method = Literal["baornn", "baornn-improved", "pinv", "dls", "qp"]


class PlannerSpec(StrictModel):
    """[planner]: the method and its parameters; keys a method does not use are ignored.

    BAORNN (both): lambda_weight Λ, beta β (Eq. 1.11), d_min (1.12), c1, c2 (1.23-1.24),
    iterations_per_step, seed; baornn-improved also `pairs`. Baselines: gain K [1/s];
    pinv/dls: repulsion η, influence [m], damping μ [m] (dls); qp: influence, safety [m].
    """

    method: Method = "baornn"
    lambda_weight: NonNegative = 0.0  # Λ of Eq. (1.11)
    beta: NonNegative = 1.0
    d_min: NonNegative = 0.0  # [m], Eq. (1.12)
    dt: Positive = 0.01  # [s] control period
    iterations_per_step: Annotated[int, Field(ge=1, le=10_000)] = 10
    duration: Positive = 50.0  # [s]
    settle: NonNegative | None = None  # [s] before rms_error and max_error; default min(5, T/2)
    tolerance: Positive = 0.05  # [m] an rms_error above it means the path was not tracked
    c1: Positive = 0.5
    c2: Positive = 0.5
    pairs: Annotated[int, Field(ge=1, le=64)] = 3
    gain: NonNegative = 20.0
    damping: NonNegative = 0.02
    repulsion: NonNegative = 0.02
    influence: Positive = 0.15
    safety: NonNegative = 0.03
    seed: Annotated[int, Field(ge=0)] = 0

    @model_validator(mode="after")
    def _times(self) -> PlannerSpec:
        if self.settle is None:
            object.__setattr__(self, "settle", min(5.0, self.duration / 2))
        if self.settle >= self.duration:
            raise field_error("settle", f"must be shorter than duration = {self.duration} s")
        if self.safety >= self.influence:
            raise field_error("safety", f"must be smaller than influence = {self.influence} m")
        return self


class PlanTables(StrictModel):
    """The [trajectory] and [planner] tables of a scene file."""

    trajectory: TrajectorySpec
    planner: PlannerSpec = PlannerSpec()


def make_planner(spec: PlannerSpec, scene: Scene) -> Planner:
    """The planner a PlannerSpec names, on `scene`."""
    rng = np.random.default_rng(spec.seed)
    objective = Objective(scene, spec.lambda_weight, spec.beta, spec.d_min)
    if spec.method == "baornn":
        return Baornn(objective, BaornnParams(spec.c1, spec.c2, spec.iterations_per_step), rng)
    if spec.method == "baornn-improved":
        params = ImprovedParams(spec.c1, spec.c2, spec.pairs, spec.iterations_per_step)
        return ImprovedBaornn(objective, params, rng)
    if spec.method == "qp":
        qp = QpIkParams(gain=spec.gain, influence=spec.influence, safety=spec.safety)
        return QpIk(scene, spec.dt, qp, spec.d_min)
    velocity = VelocityIkParams(gain=spec.gain, damping=spec.damping, repulsion=spec.repulsion,
                                influence=spec.influence)  # fmt: skip
    return VelocityIk(scene, spec.method, spec.dt, velocity, spec.d_min)


def make_trajectory(spec: TrajectorySpec, base_dir: Path) -> Circle | Waypoints:
    """The reference path a TrajectorySpec names; CSV paths are relative to `base_dir`."""
    if spec.type == "circle":
        return Circle.create(spec.center or [], spec.axis_a or [], spec.axis_b or [],
                             spec.radius or 0.0, spec.period or 0.0)  # fmt: skip
    if spec.type == "rectangle":
        return rectangle(spec.vertices or [], spec.period or 0.0)
    if spec.type == "waypoints":
        return Waypoints.create(spec.points or [], spec.times or [])
    path = Path(spec.path or "")
    return Waypoints.from_csv(path if path.is_absolute() else base_dir / path)


def plan(scene_file: Path) -> tuple[dict[str, Any], Result, float]:
    """Run the planner of a scene file: (full config, metrics and trace, wall time [s])."""
    return plan_data(load_toml(scene_file), scene_file.parent, str(scene_file))


def plan_data(
    data: dict[str, Any], base_dir: Path, where: str
) -> tuple[dict[str, Any], Result, float]:
    """plan() for a scene mapping whose relative paths start at `base_dir`; errors name `where`."""
    unknown = set(data) - {"robot", "obstacles", "trajectory", "planner"}
    if unknown:
        raise ConfigError(
            sorted(unknown)[0], "unknown table; use robot, obstacles, trajectory, planner"
        )
    if "trajectory" not in data:
        raise ConfigError(f"{where}: trajectory", "the [trajectory] table is missing")
    tables = parse_model(PlanTables, {k: data[k] for k in ("trajectory", "planner") if k in data},
                         where)  # fmt: skip
    trajectory_spec, planner_spec = tables.trajectory, tables.planner
    scene, q0 = build_scene(load_scene_spec(data, where), base_dir)
    trajectory = make_trajectory(trajectory_spec, base_dir)
    p = planner_spec
    check_reach(scene.robot, trajectory, p.duration)
    planner = make_planner(p, scene)
    start = time.perf_counter()
    result = track(planner, trajectory, q0, p.dt, p.duration)
    wall = time.perf_counter() - start
    config = {
        "experiment": "baornn.plan",
        "seed": p.seed,
        **_with_absolute_paths(data, base_dir),
        "trajectory": trajectory_spec.model_dump(mode="json", exclude_none=True),
        "planner": planner_spec.model_dump(mode="json"),
    }
    metrics = _metrics(result, scene.robot, p.settle, planner.iterations)
    if metrics["rms_error"] > p.tolerance:
        raise InfeasibleError(
            f"trajectory: not tracked: rms error {metrics['rms_error']:.3g} m after "
            f"{p.settle} s (max {metrics['max_error']:.3g} m) exceeds planner.tolerance = "
            f"{p.tolerance} m; the path may be out of reach or blocked"
        )
    return config, Result(metrics, _trace(result)), wall


def _with_absolute_paths(data: dict[str, Any], base_dir: Path) -> dict[str, Any]:
    """The [robot] and [[obstacles]] tables with file paths made absolute, so that the
    config.toml of a run folder still finds its URDF and meshes."""

    def absolute(path: str) -> str:
        return str(resolve_path(base_dir, path).resolve())

    out: dict[str, Any] = {}
    if "robot" in data:
        robot = dict(data["robot"])
        if isinstance(robot.get("urdf"), str):
            robot["urdf"] = absolute(robot["urdf"])
        if isinstance(robot.get("package_dirs"), list):
            robot["package_dirs"] = [absolute(d) for d in robot["package_dirs"]]
        out["robot"] = robot
    if "obstacles" in data:
        out["obstacles"] = [
            {**o, "mesh": absolute(o["mesh"])} if isinstance(o.get("mesh"), str) else o
            for o in data["obstacles"]
        ]
    return out


def _metrics(r: PlanResult, robot: Any, settle: float, iterations: float) -> dict[str, float]:
    """rms_error and max_error after `settle` [s]; clearance [m] and colliding steps over the
    whole run and after `settle` (the approach from q0 is the riskiest part); limits; speed."""
    settled = r.t >= settle
    late = r.error[settled]
    outside = (r.q < robot.lower) | (r.q > robot.upper)
    return {
        "settle_s": settle,
        "rms_error": float(np.sqrt(np.mean(late**2))),
        "max_error": float(late.max()),
        "min_clearance": float(r.clearance.min()),
        "min_clearance_settled": float(r.clearance[settled].min()),
        "collisions": float(np.sum(r.clearance <= 0.0)),
        "collisions_settled": float(np.sum(r.clearance[settled] <= 0.0)),
        "joint_limit_violations": float(np.sum(np.any(outside, axis=1))),
        # The planner alone: BAORNN's inner iterations, or a baseline's periods.
        "time_per_iteration_us": 1e6 * r.planner_seconds / max(iterations, 1.0),
        "time_per_period_us": 1e6 * r.planner_seconds / len(r.t),
    }


def _trace(r: PlanResult) -> dict[str, np.ndarray]:
    trace = {"t": r.t}
    trace.update({f"q_{j + 1}": r.q[:, j] for j in range(r.q.shape[1])})
    trace.update({"x": r.x[:, 0], "y": r.x[:, 1], "z": r.x[:, 2]})
    trace.update({"x_ref": r.x_ref[:, 0], "y_ref": r.x_ref[:, 1], "z_ref": r.x_ref[:, 2]})
    trace.update({"error": r.error, "clearance": r.clearance})
    return trace


def plan_to_folder(scene_file: Path, out: Path) -> dict[str, Any]:
    """Run a scene file's planner and write its run folder; returns the record."""
    config, result, wall = plan(scene_file)  # bad input fails here, before any file is written
    record = records.build_record(config, result, wall)
    records.write_run(out, config, record, result.trace)
    return record
