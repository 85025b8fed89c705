"""Generated tracking problems for the controller suite, each a scene file `articula plan` runs.

Problem i of seed S draws everything from numpy.random.default_rng([S, i]):

1. a start q0 uniform within the joint limits (shrunk by a tenth of each range; a continuous
   joint over (−π, π]), clear of the arm itself by START_SELF_CLEARANCE on the pairs of its
   allowed-collision matrix;
2. a path from the start's end-effector position: a circle (radius 5-15 cm, any plane, the
   start on it) or a line segment (10-25 cm, any direction, out and back), over 4-6 s;
   kept only if damped least squares without obstacles tracks it within REACH_RMS (so the
   path is reachable from q0 within the joint and speed limits);
3. 1-4 obstacles (a convex "rock" mesh, a box, a sphere or a capsule, 3-8 cm), each placed
   beside a link of that obstacle-free motion at a random time (from 2 cm into the link's
   surface to 5 cm out), but START_CLEARANCE from the arm at q0 and PATH_CLEARANCE (bounding
   sphere) from every point of the path.

Obstacles near the links' swept volume force the redundancy to be used; the path itself stays
free, so a controller that keeps clear can still track it. The "tight" class (issue 31) puts
2-4 obstacles each TIGHT_GAP (2-5 cm) from the links over the whole obstacle-free motion: that
motion stays clear, but every method's dampers or penalty act on it throughout. The "grazing"
class (issue 42) puts 1-2 obstacles each GRAZING_GAP from the links over that motion, whose
closest approach is within d_min (up to 1 cm into a link): the obstacle-free motion breaks
d_min, so a method tracks only if it moves the links around the obstacle along d_min.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from articula.errors import InfeasibleError
from articula.experiments.plan import NAME as PLAN
from articula.geometry.poses import pose
from articula.geometry.shapes import ConvexShape, box, capsule, convex_hull, sphere
from articula.loops.tracking import track, tracking_metrics
from articula.planning.config import TrajectorySpec, make_targets
from articula.planning.target_path import TargetPath
from articula.planning.velocity_ik import VelocityIk
from articula.robots.model import RobotModel
from articula.scene.config import build_scene, load_scene_spec
from articula.scene.obstacles import Obstacle
from articula.scene.scene import Scene
from articula.scene.self_collision import self_collision_matrix

DT = 0.01  # [s] control period
D_MIN = 0.002  # [m] hard minimum distance (BAORNN's d_min, mink's minimum_distance)
INFLUENCE = 0.15  # [m] detection distance of the dampers (qp, pinv/dls, mink)
SETTLE = 1.0  # [s] before the tracking error counts
START_CLEARANCE = 0.03  # [m] from every obstacle at q0
START_SELF_CLEARANCE = 0.01  # [m] between checked links at q0 (the Panda's wrist links sit
# about 2.2 cm apart in most poses)
PATH_CLEARANCE = 0.06  # [m] from every obstacle's bounding sphere to the path
REACH_RMS = 0.0005  # [m] obstacle-free DLS tracking that shows a path reachable
TIGHT_GAP = (0.02, 0.05)  # [m] the tight class: each obstacle's clearance from the motion
GRAZING_GAP = (-0.01, D_MIN)  # [m] the grazing class: the same, within d_min
CLASSES = ("standard", "tight", "grazing")
# Each class: (fewest obstacles, most obstacles + 1, placement gap from the chosen surface
# point [m], the closest approach over the obstacle-free motion each obstacle must keep, or
# None) [m].
PLACEMENT = {
    "standard": (1, 5, (-0.02, 0.05), None),
    "tight": (2, 5, TIGHT_GAP, TIGHT_GAP),
    "grazing": (1, 3, GRAZING_GAP, GRAZING_GAP),
}
ATTEMPTS = 100  # draws of a start, path or obstacle before the problem is given up
# The suite's common settings, and BAORNN's. Its penalty Λ/d (Eq. 1.11, β = 1) pulls harder
# than the tracking term (|∂(Λ/d)/∂d| > 1) within √Λ of an obstacle, so Λ sets how near a
# link may come before the path gives way: the book's Λ = 0.005 (7 cm) holds the arm off
# paths whose links must pass closer; 5e-5 (7 mm) acts, like the peers' dampers, within a few
# d_min (success rates at 0.005, 5e-4 and 5e-5: closing note of issue 13). c1, c2 and 10
# iterations per period are the book's.
PLANNER = {
    "lambda_weight": 5e-5,
    "beta": 1.0,
    "d_min": D_MIN,
    "dt": DT,
    "c1": 0.3,
    "c2": 0.5,
    "iterations_per_step": 10,
    "influence": INFLUENCE,
    "safety": D_MIN,
    "settle": SETTLE,
    "limits": "velocity",
    "tolerance": 1.0,
}


@dataclass(frozen=True)
class Problem:
    """A generated problem: its plan config (a scene file's tables, mesh obstacles by file
    name), the meshes to write beside it, and what kind of path it tracks.

    Attributes:
        config: the plan config: experiment, robot (q0 the drawn start), obstacles,
            trajectory and planner tables; a mesh obstacle names its file.
        meshes: the rock obstacles' meshes by file name ("rock0.stl"), to write beside it.
        path_kind: the path's kind: "circle" or "line" (out and back).
    """

    config: dict[str, Any]
    meshes: dict[str, trimesh.Trimesh]
    path_kind: str


def generate(
    robot_table: dict[str, Any], seed: int, index: int, problem_class: str = "standard"
) -> Problem:
    """Problem `index` of the suite of `seed` for the robot of a [robot] table (absolute paths).

    Raises InfeasibleError when no start, path or obstacle placement is found in ATTEMPTS
    draws (a robot whose limits leave no reachable path, say).

    Args:
        robot_table: a [robot] table with absolute paths; its q0, if any, is replaced.
        seed: the suite's seed.
        index: the problem's index; it draws from default_rng([seed, index]).
        problem_class: "standard", "tight" (obstacles TIGHT_GAP from the links) or
            "grazing" (obstacles the obstacle-free motion passes within d_min of).

    Returns:
        The problem.
    """
    rng = np.random.default_rng([seed, index])
    robot, checked = _robot(
        json.dumps({k: v for k, v in robot_table.items() if k != "q0"}, sort_keys=True)
    )
    for _ in range(ATTEMPTS):
        q0 = _start(robot, checked, rng)
        kind, trajectory, duration = _path(robot.ee_position(q0), rng)
        targets = make_targets(TrajectorySpec(**trajectory), Path.cwd())
        motion = _reachable(robot, q0, targets, duration)
        if motion is None:
            continue
        reference = np.array([targets(t).position for t in np.arange(0.0, duration, DT)])
        obstacles, meshes = _obstacles(robot, q0, motion, reference, rng, problem_class)
        if obstacles is None:
            continue
        planner = {**PLANNER, "duration": duration, "seed": seed}
        robot_out = {k: v for k, v in robot_table.items() if k != "q0"} | {"q0": q0.tolist()}
        config = {
            "experiment": PLAN,
            "robot": robot_out,
            "obstacles": obstacles,
            "trajectory": trajectory,
            "planner": planner,
        }
        return Problem(config, meshes, kind)
    raise InfeasibleError(
        f"no problem found in {ATTEMPTS} draws (start, reachable path, obstacle placement)",
        "robot",
    )


@cache
def _robot(table_json: str) -> tuple[RobotModel, Scene]:
    """The robot of a [robot] table (as JSON: a cache key) and a scene checking its
    allowed-collision pairs; built once per process."""
    scene, _ = build_scene(load_scene_spec({"robot": json.loads(table_json)}), Path.cwd())
    robot = scene.robot
    pairs = self_collision_matrix(robot).checked
    return robot, Scene(robot, [], self_pairs=pairs)


def _start(robot: RobotModel, checked: Scene, rng: np.random.Generator) -> np.ndarray:
    """A start within the shrunk limits (a continuous joint anywhere in (−π, π]: its limits
    are ±inf), START_SELF_CLEARANCE clear of the arm itself."""
    lower, upper = robot.sample_range
    margin = np.where(robot.continuous, 0.0, 0.1 * (upper - lower))
    for _ in range(ATTEMPTS):
        # uniform draws [−π, π) on a continuous joint; wrap sends −π to π
        q0 = robot.wrap(rng.uniform(lower + margin, upper - margin))
        if not checked.self_pairs or checked.clearances(q0)[1] > START_SELF_CLEARANCE:
            return q0
    raise InfeasibleError(f"no self-collision-free start in {ATTEMPTS} draws", "robot")


def _path(x0: np.ndarray, rng: np.random.Generator) -> tuple[str, dict[str, Any], float]:
    """A circle through x0 or a segment out of x0 and back: its kind, [trajectory] table and
    duration [s] (one lap)."""
    period = float(rng.uniform(4.0, 6.0))
    u, v = np.linalg.qr(rng.standard_normal((3, 2)))[0].T  # orthonormal
    if rng.random() < 0.5:
        radius = float(rng.uniform(0.05, 0.15))
        center = x0 - radius * u  # Eq. (1.27) starts at center + radius·axis_a
        table = {
            "type": "circle",
            "center": center.tolist(),
            "axis_a": u.tolist(),
            "axis_b": v.tolist(),
            "radius": radius,
            "period": period,
        }
        return "circle", table, period
    end = x0 + float(rng.uniform(0.10, 0.25)) * u
    points = [x0.tolist(), end.tolist(), x0.tolist()]
    table = {"type": "waypoints", "points": points, "times": [0.0, period / 2, period]}
    return "line", table, period


def _reachable(
    robot: RobotModel, q0: np.ndarray, targets: TargetPath, duration: float
) -> np.ndarray | None:
    """The joint motion [rad] (periods × nq) of obstacle-free DLS along the path, or None when
    it does not track within REACH_RMS."""
    planner = VelocityIk(Scene(robot, []), "dls", DT)
    run = track(planner, targets, q0, DT, duration, 10**6)
    metrics = tracking_metrics(run, robot, SETTLE, planner.iterations)
    if metrics["rms_error"] > REACH_RMS or metrics["joint_limit_violations"] > 0:
        return None
    return run.q


def _obstacles(
    robot: RobotModel,
    q0: np.ndarray,
    motion: np.ndarray,
    reference: np.ndarray,
    rng: np.random.Generator,
    problem_class: str,
) -> tuple[list[dict[str, Any]] | None, dict[str, trimesh.Trimesh]]:
    """The class's obstacles beside the motion's links (PLACEMENT: standard 1-4; tight 2-4,
    each TIGHT_GAP from them over the whole motion; grazing 1-2, each GRAZING_GAP), as
    [[obstacles]] tables and mesh files; None when one cannot be placed."""
    tables, meshes, placed = [], {}, []
    links = [link for link in robot.links if robot.model.frames[link.frame_id].parentJoint != 0]
    fewest, most, gap, closest = PLACEMENT[problem_class]
    for k in range(int(rng.integers(fewest, most))):
        kind = ("rock", "box", "sphere", "capsule")[int(rng.integers(4))]
        for _ in range(ATTEMPTS):
            shape, table, mesh = _shape(kind, float(rng.uniform(0.03, 0.08)), rng)
            q = motion[int(rng.integers(len(motion)))]
            link = links[int(rng.integers(len(links)))]
            T = robot.link_poses(q)[link.name]
            s = int(rng.integers(len(link.shapes)))
            core = link.shapes[s].vertices
            world = (T @ link.placements[s] @ np.c_[core, np.ones(len(core))].T).T[:, :3]
            surface = world[int(rng.integers(len(world)))]
            out = surface - world.mean(axis=0)
            out = out / max(np.linalg.norm(out), 1e-9) + 0.5 * _unit(rng)
            extent = float(np.max(np.linalg.norm(shape.vertices, axis=1)))
            centre = surface + out / np.linalg.norm(out) * (extent + rng.uniform(*gap))
            if np.min(np.linalg.norm(reference - centre, axis=1)) - extent < PATH_CLEARANCE:
                continue
            rpy = Rotation.random(random_state=rng).as_euler("xyz")
            obstacle = Obstacle(f"{kind}{k}", (shape,), pose(centre, rpy))
            if Scene(robot, [*placed, obstacle]).clearances(q0)[0] <= START_CLEARANCE:
                continue
            if closest is not None and not _within_gap(Scene(robot, [obstacle]), motion, closest):
                continue
            placed.append(obstacle)
            name = f"{kind}{k}"
            tables.append({"name": name, **table, "position": centre.tolist(), "rpy": rpy.tolist()})
            if mesh is not None:
                tables[-1]["mesh"] = f"{name}.stl"
                meshes[f"{name}.stl"] = mesh
            break
        else:
            return None, {}
    return tables, meshes


def _within_gap(scene: Scene, motion: np.ndarray, gap: tuple[float, float]) -> bool:
    """Whether the scene's one obstacle's closest approach to the links over the motion is
    within `gap` [m]."""
    closest = min(scene.clearances(q)[0] for q in motion)
    return gap[0] <= closest <= gap[1]


def _shape(
    kind: str, size: float, rng: np.random.Generator
) -> tuple[ConvexShape, dict[str, Any], trimesh.Trimesh | None]:
    """An obstacle shape of about `size` [m], its [[obstacles]] shape key and, for a rock, its
    mesh (the hull of 24 points on an ellipsoid)."""
    if kind == "rock":
        axes = size * rng.uniform(0.6, 1.0, 3)
        points = np.array([_unit(rng) for _ in range(24)]) * axes
        mesh = trimesh.convex.convex_hull(points)
        return convex_hull(np.asarray(mesh.vertices)), {}, mesh
    if kind == "box":
        sides = 2 * size * rng.uniform(0.5, 1.0, 3)
        return box(tuple(sides)), {"box": sides.tolist()}, None
    if kind == "sphere":
        return sphere(size), {"sphere": size}, None
    radius, length = 0.5 * size, 1.5 * size
    return capsule(radius, length), {"capsule": [radius, length]}, None


def _unit(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random unit vector."""
    v = rng.standard_normal(3)
    return v / math.sqrt(v @ v)
