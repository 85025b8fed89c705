"""The planning experiment `baornn.plan`: a scene, a reference path and a planner, tracked.

A plan config is a scene file ([robot], [[obstacles]]) with a [trajectory] and a [planner]
table, and optionally `experiment = "baornn.plan"` and a top-level `seed`. `articula plan
SCENE.toml` and `articula run CONFIG.toml` both run it through the shared runner, so a plan
folder's config.toml re-runs and sweeps like any other experiment's.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import model_validator

from articula.errors import ConfigError, InfeasibleError
from articula.loops.tracking import Trajectory, trace_columns, track, tracking_metrics
from articula.planning.approach import approach
from articula.planning.config import (
    PlannerSpec,
    TrajectorySpec,
    absolute_paths,
    make_planner,
    make_targets,
)
from articula.planning.reach import check_reach
from articula.planning.task import Target
from articula.runs.registry import Experiment, Progress, Result
from articula.scene.config import SceneSpec, build_scene
from articula.validation import Seed, fields_as, load_toml

NAME = "baornn.plan"
# Library argument names -> where the user wrote them in a plan config.
_CONFIG_PATHS = {"q0": "robot.q0", "dt": "planner.dt", "duration": "planner.duration"}


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
    """

    seed: Seed | None = None
    trajectory: TrajectorySpec
    planner: PlannerSpec = PlannerSpec()

    @model_validator(mode="after")
    def _one_seed(self) -> PlanConfig:
        seed = self.seed if self.seed is not None else self.planner.seed
        object.__setattr__(self, "seed", 0 if seed is None else seed)
        object.__setattr__(self, "planner", self.planner.model_copy(update={"seed": None}))
        return self


def run_plan(config: PlanConfig, progress: Progress | None = None) -> Result:
    """Track the path; metrics of loops.tracking.tracking_metrics and its trace columns.

    Relative file paths start at the working folder (a config read from a file has them made
    absolute by `absolute_paths`).

    Args:
        config: the validated plan config.
        progress: called as progress(done, total) every hundredth of the run; None: silent.

    Returns:
        The metrics of tracking_metrics (rms_error and max_error after `planner.settle` [m],
            clearances [m], collisions, joint-limit violations, planner timings) and the
            trace columns of trace_columns (t [s], q_1..q_m [rad], x, y, z, their references
            x_ref, y_ref, z_ref, error and clearance [m]).

    Raises:
        InfeasibleError: the path is out of the robot's reach, or its rms_error after
            `planner.settle` exceeds `planner.tolerance`.
    """
    base = Path.cwd()
    scene, q0 = build_scene(config, base)
    targets = make_targets(config.trajectory, base)
    p = config.planner
    with fields_as(_CONFIG_PATHS):
        check_reach(scene.robot, targets.positions, p.duration)
        planner = make_planner(p, scene, config.seed)
        reference: Trajectory = targets
        lead = 0.0
        if p.approach == "auto":
            pose = scene.robot.ee_pose(scene.robot.check_q(q0, "q0"))
            tool = Target(pose[:3, 3], pose[:3, :3], pose[:3, :3] @ planner.task.tool_axis)
            reference = approach(targets, tool, p.approach_speed, p.approach_turn_rate)
            lead = reference.duration
        run = track(planner, reference, q0, p.dt, lead + p.duration, p.max_steps, progress,
                    lead)  # fmt: skip
    metrics = tracking_metrics(run, scene.robot, p.settle or 0.0, planner.iterations, targets.cone)
    after = f"{p.settle} s into the path" if lead else f"{p.settle} s"
    if metrics["rms_error"] > p.tolerance:
        raise InfeasibleError(
            f"not tracked: rms error {metrics['rms_error']:.3g} m after {after} (max "
            f"{metrics['max_error']:.3g} m) exceeds planner.tolerance = {p.tolerance} m; the "
            "path may be out of reach or blocked",
            "trajectory",
        )
    turned = metrics.get("rms_orientation_error")
    if turned is not None and turned > p.orientation_tolerance:
        raise InfeasibleError(
            f"not tracked: rms orientation error {turned:.3g} rad after {after} (max "
            f"{metrics['max_orientation_error']:.3g} rad) exceeds planner.orientation_tolerance "
            f"= {p.orientation_tolerance} rad",
            "trajectory",
        )
    return Result(metrics, trace_columns(run))


def load_plan(path: Path) -> dict[str, Any]:
    """A scene file (or a plan folder's config.toml) as a `baornn.plan` config, its file paths
    made absolute.

    Args:
        path: the scene file or config.toml; its relative paths start at its folder.

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
    return absolute_paths(data, path.parent)


PLAN = Experiment(NAME, PlanConfig, run_plan, absolute_paths)
