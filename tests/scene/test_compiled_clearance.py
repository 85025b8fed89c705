"""scene/compiled_clearance.py: the compiled clearance and end-effector position against Pinocchio
+ coal, on meshes and primitives; warm starts; the scenes it leaves to coal."""

from __future__ import annotations

import numpy as np
import pytest

from articula.geometry.poses import pose
from articula.geometry.shapes import box, capsule, cylinder, sphere
from articula.robots import RobotModel
from articula.robots.sweep import joint_sweep
from articula.scene import Obstacle, Scene
from articula.scene.compiled_clearance import CompiledClearance, _evaluate
from tests.scene.helpers import book_scene

ROBOT = RobotModel.builtin("iiwa14")


def test_mesh_scene_agrees_with_coal_including_overlaps():
    scene = book_scene("circle_two_obstacles")
    compiled = CompiledClearance.build(scene)
    assert compiled is not None
    rng = np.random.default_rng(7)
    overlaps = 0
    for q in rng.uniform(ROBOT.lower, ROBOT.upper, (400, ROBOT.nq)):
        d, d_self, ee, ee_R = compiled.evaluate(q)
        assert d_self == np.inf  # no self pairs in this scene
        assert np.allclose(ee_R, ROBOT.ee_pose(q)[:3, :3], atol=1e-12)
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


def test_warm_start_does_not_change_the_answer():
    scene = book_scene("circle_two_obstacles")
    rng = np.random.default_rng(3)
    Q = rng.uniform(ROBOT.lower, ROBOT.upper, (100, ROBOT.nq))
    warm = CompiledClearance.build(scene)
    first = [warm.evaluate(q)[0] for q in Q]
    again = [warm.evaluate(q)[0] for q in Q[::-1]][::-1]  # other hints and simplices
    assert np.allclose(first, again, atol=1e-9, rtol=0)


def test_small_steps_reuse_memory_and_simplices_without_changing_the_answer():
    # A search's evaluations are close together: the remembered bounds and the cached GJK
    # simplices do the work there, so check them along a smooth path through near-contacts.
    scene = book_scene("circle_two_obstacles")
    compiled = CompiledClearance.build(scene)
    start, end = np.zeros(ROBOT.nq), np.array([0.9, 0.8, 0.5, -1.2, 0.4, 0.9, 0.2])
    for s in np.linspace(0.0, 1.0, 300):
        q = start + s * (end - start) + 0.002 * np.sin(40 * s + np.arange(ROBOT.nq))
        assert compiled.evaluate(q)[0] == pytest.approx(max(scene.min_distance(q), 0.0), abs=1e-6)


def test_cylinders_have_no_compiled_form():
    round_rim = Obstacle("c", (cylinder(0.05, 0.2),), pose([0.3, 0.3, 0.5]))
    assert CompiledClearance.build(Scene(ROBOT, [round_rim])) is None


def test_a_moving_obstacle_is_where_its_pose_puts_it_at_each_time():
    # A box sweeping past the arm, and one at rest: the compiled distance follows the box
    # (at(t)) as coal's does, also when a time comes back.
    moving = Obstacle("m", (box((0.1, 0.2, 0.1)),), lambda t: pose([0.2 + 0.1 * t, 0.4, 0.6]))
    still = Obstacle("s", (sphere(0.05),), pose([-0.4, 0.0, 0.9]))
    scene = Scene(ROBOT, [moving, still])
    compiled = CompiledClearance.build(scene)
    q = np.array([0.3, 0.5, 0.0, -1.0, 0.0, 0.6, 0.0])
    for t in (0.0, 1.0, 2.5, 4.0, 1.0, *np.linspace(1.0, 1.2, 20)):
        compiled.at(t)
        assert compiled.evaluate(q)[0] == pytest.approx(scene.min_distance(q, t), abs=1e-7)


def test_self_pairs_agree_with_coal_and_stay_apart_from_obstacles():
    pairs = [("iiwa_link_0", "iiwa_link_5"), ("iiwa_link_1", "iiwa_link_6"),
             ("iiwa_link_5", "iiwa_link_7"), ("iiwa_link_2", "iiwa_link_7")]  # fmt: skip
    obstacle = Obstacle("o", (sphere(0.07),), pose([0.3, 0.3, 0.6]))
    scene = Scene(ROBOT, [obstacle], self_pairs=pairs)
    compiled = CompiledClearance.build(scene)
    rng = np.random.default_rng(11)
    touching = 0
    for q in rng.uniform(ROBOT.lower, ROBOT.upper, (300, ROBOT.nq)):
        d, d_self, _, _ = compiled.evaluate(q)
        obstacles, itself = scene.clearances(q)
        assert itself == pytest.approx(scene.self_distances(q).min(), abs=1e-12)
        touching += itself <= 0
        assert d == pytest.approx(max(obstacles, 0.0), abs=1e-6)
        assert d_self == pytest.approx(max(itself, 0.0), abs=1e-6)
        only_self = compiled.evaluate(q, obstacles=False)
        assert only_self[0] == np.inf
        assert only_self[1] == pytest.approx(d_self, abs=1e-12)
    assert touching > 0  # the sample did reach self-overlap


def test_near_pairs_keep_every_pair_that_can_be_the_minimum_in_the_box():
    far = [Obstacle(f"far{k}", (sphere(0.1),), pose([2.0 * np.cos(k), 2.0 * np.sin(k), 0.5]))
           for k in range(4)]  # fmt: skip
    within_reach = [Obstacle(f"reach{k}", (sphere(0.05),), pose([0.9 * np.cos(k), 0.9 * np.sin(k),
                                                                0.4 + 0.1 * k]))
                    for k in range(4)]  # fmt: skip
    near = Obstacle("near", (box((0.1, 0.2, 0.15)),), pose([0.3, 0.3, 0.6], [0.3, -0.2, 0.5]))
    scene = Scene(ROBOT, [near, *far, *within_reach])
    compiled = CompiledClearance.build(scene)
    rng = np.random.default_rng(8)
    dropped = {"reach": 0, "sweep": 0}
    for centre in rng.uniform(0.8 * ROBOT.lower, 0.8 * ROBOT.upper, (30, ROBOT.nq)):
        width = 0.015  # one 10 ms period at 1.5 rad/s
        lower, upper = centre - width, centre + width
        for name, sweep in (("reach", None), ("sweep", joint_sweep(ROBOT))):
            kept = compiled.near_pairs(compiled.pairs, (lower, upper), sweep)
            dropped[name] += len(compiled.pairs) - len(kept)
            for q in rng.uniform(lower, upper, (5, ROBOT.nq)):
                every = _evaluate(q, compiled.inputs(), compiled.static_min)[0]
                near_only = _evaluate(q, compiled.inputs(kept), compiled.static_min)[0]
                assert near_only == pytest.approx(every, abs=1e-9)
    assert dropped["reach"] >= 30 * 4 * 7  # the far spheres' pairs, at least, left every box
    # Per joint, the box's distal joints count for what they move: more pairs left out.
    assert dropped["sweep"] > 1.2 * dropped["reach"]
    # The nearest pair's exact distance at the centre caps the ceiling: 1235 and 1750 pairs
    # left out over these boxes, against 1107 and 1697 with the balls around a vertex alone.
    assert dropped["reach"] > 1200 and dropped["sweep"] > 1740
