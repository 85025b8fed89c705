"""Cost of link-obstacle distances for the iiwa14 among two mesh obstacles (issue targets).

    python benchmarks/distance.py [--json]

Scene: src/articula/book/ch1/configs/two_obstacles.toml (a bracket and a rock in front
of the robot, Figs. 1.11-1.12 style). Configurations: random joint vectors within 60 % of the
limits with the robot clear of both obstacles (the planner's usual situation). For each, the
median time of one call:
  min_distance_us    Scene.min_distance(q), no broad phase (every pair by GJK/EPA)
  broadphase_us      Scene.min_distance(q) with the bounding-capsule broad phase (default)
  bare_coal_us       the same work written as a bare loop: Pinocchio forward kinematics, then
                     coal.distance on every (link, obstacle) pair from Python
  vertex_formula_us  the book's Sect. 1.3.3 closest-vertex-pair formula (metric="vertex")
Targets: broad phase <= 10 us; min_distance_us <= 1.3 x bare_coal_us; broadphase_us <
bare_coal_us.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
from common import run

from articula.book.study import packaged
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

CONFIGS = 2000
REPEATS = 5


def _scene_file() -> Path:
    return packaged("ch1", "two_obstacles.toml")


def _median_us(fn, Q: np.ndarray) -> float:
    """Median over configurations of the best of REPEATS timings of fn(q)."""
    times = []
    clock = time.perf_counter_ns
    for q in Q:
        best = min(_time_once(fn, q, clock) for _ in range(REPEATS))
        times.append(best)
    return statistics.median(times) / 1e3


def _time_once(fn, q, clock) -> int:
    start = clock()
    fn(q)
    return clock() - start


def bare_coal_loop(scene):
    """min distance by Pinocchio FK and coal.distance on every pair, from Python."""
    robot = scene.robot
    model, data = robot.model, robot.data
    links = []
    for link in robot.links:
        for shape, T in zip(link.shapes, link.placements, strict=True):
            links.append((link.frame_id, pin.SE3(T), shape.geometry, coal.Transform3s()))
    obstacles = []
    for obstacle in scene.obstacles:
        T = obstacle.pose_at(0.0)
        for part in obstacle.parts:
            obstacles.append((part.geometry, coal.Transform3s(T[:3, :3], T[:3, 3])))
    request = coal.DistanceRequest()
    request.enable_signed_distance = True
    result = coal.DistanceResult()

    def min_distance(q: np.ndarray) -> float:
        pin.framesForwardKinematics(model, data, q)
        best = np.inf
        for frame_id, local, geometry, tf in links:
            M = data.oMf[frame_id] * local
            tf.setRotation(M.rotation)
            tf.setTranslation(M.translation)
            for obstacle_geometry, obstacle_tf in obstacles:
                result.clear()
                d = coal.distance(geometry, tf, obstacle_geometry, obstacle_tf, request, result)
                best = min(best, d)
        return best

    return min_distance


def measure() -> dict[str, float]:
    path = _scene_file()
    spec = load_scene_spec(load_toml(path))
    broad, _ = build_scene(spec, path.parent, broadphase=True)
    full, _ = build_scene(spec, path.parent, broadphase=False)
    vertex, _ = build_scene(spec, path.parent, metric="vertex")
    robot = broad.robot
    rng = np.random.default_rng(0)
    candidates = rng.uniform(0.6 * robot.lower, 0.6 * robot.upper, size=(4 * CONFIGS, robot.nq))
    clear = candidates[full.min_distance_batch(candidates) > 0.0][:CONFIGS]
    bare = bare_coal_loop(full)
    agree = max(abs(bare(q) - full.min_distance(q)) for q in clear[:200])
    return {
        "configurations": float(len(clear)),
        "min_distance_us": _median_us(full.min_distance, clear),
        "broadphase_us": _median_us(broad.min_distance, clear),
        "bare_coal_us": _median_us(bare, clear),
        "vertex_formula_us": _median_us(vertex.min_distance, clear[:200]),
        "bare_vs_library_max_abs_diff_m": float(agree),
    }


def table(m: dict[str, float]) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person, each against the bare coal loop."""
    bare = m["bare_coal_us"]

    def row(name: str, key: str, target: str) -> list[str]:
        return [name, f"{m[key]:.2f}", f"{m[key] / bare:.2f}", target]

    rows = [
        ["bare coal loop (baseline)", f"{bare:.2f}", "1.00", ""],
        row("min_distance, no broad phase", "min_distance_us", "<= 1.3"),
        row("min_distance, broad phase", "broadphase_us", "< 1, <= 10 µs"),
        row("book's vertex-pair formula", "vertex_formula_us", ""),
        ["largest |bare - library| [m]", f"{m['bare_vs_library_max_abs_diff_m']:.2e}", "", ""],
    ]
    title = (
        "iiwa14 vs two mesh obstacles: median per configuration over "
        f"{int(m['configurations'])} configurations"
    )
    return title, ["method", "µs", "× bare coal loop", "target"], rows


if __name__ == "__main__":
    run(__doc__, measure, table)
