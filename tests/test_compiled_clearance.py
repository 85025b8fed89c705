"""The compiled objective path (scene/gjk.py, scene/compiled_clearance.py, baornn_kernel.py)
against Pinocchio + coal, closed forms, and the Python BAORNN loop."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.geometry.poses import pose
from articula.geometry.shapes import box, capsule, convex_hull, cylinder, sphere
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.baornn_improved import ImprovedBaornn, ImprovedParams
from articula.planning.objective import Objective
from articula.planning.trajectories import Circle
from articula.robots import RobotModel
from articula.scene import Obstacle, Scene
from articula.scene.compiled_clearance import CompiledClearance
from articula.scene.config import build_scene, load_scene_spec
from articula.scene.gjk import gjk_distance
from articula.validation import load_toml

CONFIGS = Path(__file__).resolve().parents[1] / "src/articula/experiments/configs/ch1"
ROBOT = RobotModel.builtin("iiwa14")


def _two_obstacles() -> Scene:
    path = CONFIGS / "circle_two_obstacles.toml"
    return build_scene(load_scene_spec(load_toml(path)), path.parent)[0]


def test_mesh_scene_agrees_with_coal_including_overlaps():
    scene = _two_obstacles()
    compiled = CompiledClearance.build(scene)
    assert compiled is not None
    rng = np.random.default_rng(7)
    overlaps = 0
    for q in rng.uniform(ROBOT.lower, ROBOT.upper, (400, ROBOT.nq)):
        d, ee = compiled.evaluate(q)
        reference = scene.min_distance(q)
        overlaps += reference <= 0
        # coal's GJK stops at its own tolerance; overlaps are clearance 0 here.
        assert d == pytest.approx(max(reference, 0.0), abs=1e-6)
        assert np.allclose(ee, ROBOT.ee_position(q), atol=1e-12)
    assert overlaps > 0  # the sample did test the overlapping case


@pytest.mark.parametrize(
    "part",
    [sphere(0.07), capsule(0.05, 0.3), box((0.1, 0.2, 0.15))],
    ids=["sphere", "capsule", "box"],
)
def test_primitive_obstacles_agree_with_coal(part):
    obstacle = Obstacle("o", (part,), pose([0.3, 0.3, 0.6], [0.3, -0.2, 0.5]))
    scene = Scene(ROBOT, [obstacle])
    compiled = CompiledClearance.build(scene)
    rng = np.random.default_rng(1)
    for q in rng.uniform(ROBOT.lower, ROBOT.upper, (150, ROBOT.nq)):
        assert compiled.evaluate(q)[0] == pytest.approx(max(scene.min_distance(q), 0.0), abs=1e-6)


def test_gjk_closed_forms():
    # Two unit cubes (one core, posed twice) at known offsets.
    corners = np.array(np.meshgrid([-0.5, 0.5], [-0.5, 0.5], [-0.5, 0.5])).reshape(3, -1).T
    cube = convex_hull(corners)
    part = Scene(ROBOT, [Obstacle("a", (cube,), np.eye(4))])
    c = CompiledClearance.build(part)
    k = len(ROBOT.links)  # the cube is the first shape after the links
    args = (c.vertices, c.neighbours, c.offsets, c.hints.copy())
    eye = np.eye(3)
    d = gjk_distance(*args, k, eye, np.zeros(3), 0.0, k, eye, np.array([1.5, 0.0, 0.0]), 0.0,
                     np.zeros(3))  # fmt: skip
    assert d == pytest.approx(0.5, abs=1e-12)
    # Corner to corner along the diagonal: sqrt(3)·(s − 1) for centres s·(1,1,1) apart.
    d = gjk_distance(*args, k, eye, np.zeros(3), 0.0, k, eye, np.full(3, 1.4), 0.0, np.zeros(3))
    assert d == pytest.approx(np.sqrt(3) * 0.4, abs=1e-12)
    # The same cube swept by radii 0.1 and 0.2 loses 0.3; overlapping cubes give 0.
    d = gjk_distance(*args, k, eye, np.zeros(3), 0.1, k, eye, np.array([1.5, 0.0, 0.0]), 0.2,
                     np.zeros(3))  # fmt: skip
    assert d == pytest.approx(0.2, abs=1e-12)
    d = gjk_distance(*args, k, eye, np.zeros(3), 0.0, k, eye, np.array([0.9, 0.1, 0.0]), 0.0,
                     np.zeros(3))  # fmt: skip
    assert d == 0.0


def test_warm_start_does_not_change_the_answer():
    scene = _two_obstacles()
    rng = np.random.default_rng(3)
    Q = rng.uniform(ROBOT.lower, ROBOT.upper, (100, ROBOT.nq))
    warm = CompiledClearance.build(scene)
    first = [warm.evaluate(q)[0] for q in Q]
    again = [warm.evaluate(q)[0] for q in Q[::-1]][::-1]  # other hints and guesses
    assert np.allclose(first, again, atol=1e-9, rtol=0)


def test_unsupported_scenes_fall_back_to_coal():
    moving = Obstacle("m", (sphere(0.05),), lambda t: pose([0.3, 0.3, 0.5 + 0.01 * t]))
    assert CompiledClearance.build(Scene(ROBOT, [moving])) is None
    round_rim = Obstacle("c", (cylinder(0.05, 0.2),), pose([0.3, 0.3, 0.5]))
    assert CompiledClearance.build(Scene(ROBOT, [round_rim])) is None
    scene = Scene(ROBOT, [moving])
    objective = Objective(scene, 0.001, 1.0, 0.0)
    assert objective.compiled is None
    q = np.zeros(ROBOT.nq)
    expected = np.linalg.norm(np.array([0.2, 0.6, 0.5]) - ROBOT.ee_position(q)) + 0.001 / (
        scene.min_distance(q)
    )
    assert objective.value(q, np.array([0.2, 0.6, 0.5])) == pytest.approx(expected)


def test_compiled_baornn_follows_the_python_loop():
    scene = _two_obstacles()
    circle = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)
    runs = []
    for compiled in (True, False):
        objective = Objective(scene, 0.005, 1.0, 0.002, use_compiled=compiled)
        planner = Baornn(objective, BaornnParams(0.3, 0.5, 10), np.random.default_rng(4))
        q = np.zeros(ROBOT.nq)
        qs = []
        for n in range(60):
            q = planner.step(q, circle(0.01 * n), 0.01 * n)
            qs.append(q.copy())
        runs.append(np.array(qs))
        assert planner.iterations == 600 and planner.evaluations == 1800
    # The two distance codes agree to ~1e-7 m, so the accepted steps are the same ones.
    assert np.allclose(runs[0], runs[1], atol=1e-6)


def test_a_point_inside_an_obstacle_is_outside_omega_on_both_paths():
    # Ω is d > d_min (Eq. 1.12): with d_min = 0 an overlapping antenna stays at (θ_k, g_k) on
    # the compiled path (clearance 0) as on the coal path (negative signed distance).
    scene = _two_obstacles()
    rng = np.random.default_rng(11)
    overlapping = next(
        q for q in rng.uniform(ROBOT.lower, ROBOT.upper, (500, ROBOT.nq))
        if scene.min_distance(q) < 0
    )  # fmt: skip
    current, x_ref = np.zeros(ROBOT.nq), np.array([0.2, 0.6, 0.5])
    for compiled in (True, False):
        objective = Objective(scene, 0.005, 1.0, 0.0, use_compiled=compiled)
        assert (objective.compiled is not None) == compiled
        q, g = objective.project_and_value(overlapping, current, 1.25, x_ref, 0.0)
        assert q is current and g == 1.25


def test_compiled_improved_variant_follows_its_python_loop():
    # The same draws and steps; the two distance codes differ by ~1e-7 m, which a continuous
    # gradient estimate carries into q at ~1e-9 rad over the first steps.
    scene = _two_obstacles()
    circle = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)
    runs = []
    for compiled in (True, False):
        objective = Objective(scene, 0.005, 1.0, 0.002, use_compiled=compiled)
        params = ImprovedParams(0.3, 0.5, 3, 2)
        planner = ImprovedBaornn(objective, params, np.random.default_rng(4))
        q = np.zeros(ROBOT.nq)
        qs = []
        for n in range(20):
            q = planner.step(q, circle(0.01 * n), 0.01 * n)
            qs.append(q.copy())
        runs.append(np.array(qs))
        assert planner.iterations == 40
    assert np.allclose(runs[0], runs[1], atol=1e-6)
