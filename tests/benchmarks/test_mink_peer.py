"""bench/mink_model.py, mink_peer.py: mink's MuJoCo model is articula's arm and obstacles, and
benchmarks/peers.py runs (skipped without the `peers` extra)."""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from scipy.spatial import cKDTree

from articula.book.study import packaged
from articula.planning.trajectories import Circle
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml
from tests.benchmarks.run import benchmark

INSTALL = "pip install -e '.[peers]'"
pytest.importorskip("mujoco", reason=INSTALL)
pytest.importorskip("mink", reason=INSTALL)

peer = importlib.import_module("articula.bench.mink_peer")
mink_model = importlib.import_module("articula.bench.mink_model")

D_MIN, DETECTION, DT = 0.002, 0.15, 0.01
CIRCLE = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)


@pytest.fixture(scope="module")
def scene_q0():
    path = packaged("ch1", "circle_two_obstacles.toml")
    return build_scene(load_scene_spec(load_toml(path)), path.parent)


def _configurations(scene, count=20):
    rng = np.random.default_rng(7)
    return rng.uniform(scene.robot.lower, scene.robot.upper, size=(count, scene.robot.nq))


def test_link_frames_and_end_effector_agree_with_articula(scene_q0):
    scene, _ = scene_q0
    arm = peer.MinkArm(scene, D_MIN, DETECTION, DT)
    for q in _configurations(scene):
        np.testing.assert_array_equal(arm.reset(q), q)
        poses = scene.robot.link_poses(q)
        for link in scene.robot.links:
            mine = arm.site_pose(mink_model.link_site(link.name))
            np.testing.assert_allclose(mine, poses[link.name], rtol=0, atol=1e-9)
        np.testing.assert_allclose(
            arm.site_pose(mink_model.EE_SITE), scene.robot.ee_pose(q), atol=1e-9
        )
        np.testing.assert_allclose(arm.ee_position(), scene.robot.ee_position(q), atol=1e-9)


def test_every_geom_is_articulas_hull_and_mujoco_collides_with_all_its_vertices(scene_q0):
    scene, _ = scene_q0
    arm = peer.MinkArm(scene, D_MIN, DETECTION, DT)
    for q in _configurations(scene, 5):
        arm.reset(q)
        poses = scene.robot.link_poses(q)
        for link in scene.robot.links:
            for k, (shape, T) in enumerate(zip(link.shapes, link.placements, strict=True)):
                W = poses[link.name] @ T
                ours = shape.vertices @ W[:3, :3].T + W[:3, 3]
                name = mink_model.link_geom(link.name, k)
                _same_points(ours, arm.geom_vertices(name))
                _same_points(ours, arm.hull_vertices(name))  # no hull vertex lost or added
    for obstacle in scene.obstacles:
        W = obstacle.pose_at(0.0)
        for k, part in enumerate(obstacle.parts):
            name = mink_model.obstacle_geom(obstacle.name, k)
            _same_points(part.vertices @ W[:3, :3].T + W[:3, 3], arm.hull_vertices(name))


def _same_points(a, b, tol=5e-8):
    """The same point sets to `tol` [m]: MuJoCo keeps mesh vertices in float32 (≈ 1e-8 m)."""
    assert len(a) == len(b)
    assert cKDTree(a).query(b)[0].max() < tol
    assert cKDTree(b).query(a)[0].max() < tol


def test_mujoco_distances_are_articulas_and_every_moving_link_obstacle_pair_is_kept(scene_q0):
    scene, _ = scene_q0
    arm = peer.MinkArm(scene, D_MIN, DETECTION, DT)
    model = arm.model
    pairs = {tuple(sorted(p)) for p in arm.collision.geom_id_pairs}
    moving = [g for g in arm.link_geoms if model.body_weldid[model.geom(g).bodyid[0]] != 0]
    expected = {
        tuple(sorted((model.geom(a).id, model.geom(b).id)))
        for a in moving
        for b in arm.obstacle_geoms
    }
    assert len(moving) == len(arm.link_geoms) - 1  # iiwa_link_0 is the base, welded to the world
    assert pairs == expected
    for q in _configurations(scene, 10):
        arm.reset(q)
        D = scene.distances(q)
        for li, link in enumerate(scene.robot.links):
            for oi, obstacle in enumerate(scene.obstacles):
                if D[li, oi] <= 0:
                    continue  # penetration depths: EPA against MuJoCo's own, not compared
                d = arm.distance(mink_model.link_geom(link.name, 0),
                                 mink_model.obstacle_geom(obstacle.name, 0),
                                 within=10.0)  # fmt: skip
                assert d == pytest.approx(D[li, oi], abs=1e-5)  # MuJoCo's CCD tolerance 1e-6


def test_a_moved_obstacle_is_where_it_was_put(scene_q0):
    scene, q0 = scene_q0
    arm = peer.MinkArm(scene, D_MIN, DETECTION, DT)
    q = arm.reset(q0)
    rock = next(o for o in scene.obstacles if o.name == "rock")
    pose = rock.pose_at(0.0).copy()
    pose[:3, :3] = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    pose[:3, 3] += [0.5, 0.2, 0.1]
    arm.step(scene.robot.ee_position(q), {"rock": pose})
    _same_points(rock.parts[0].vertices @ pose[:3, :3].T + pose[:3, 3],
                 arm.hull_vertices(mink_model.obstacle_geom("rock", 0)))  # fmt: skip


def test_mink_keeps_d_min_past_the_bracket_with_a_damper_gain(scene_q0):
    """mink's CollisionAvoidanceLimit bounds a displacement Δq by gain (d − d_min) / dt, so its
    default gain 0.85 lets the arm close 85 (d − d_min) per 10 ms period and the forearm goes
    into the bracket at 0.54 s here; with the gain of a damper (a rate of 1 m/s over the
    detection band, × dt²) every period keeps d_min, and the path is still tracked."""
    scene, q0 = scene_q0
    arm = peer.MinkArm(scene, D_MIN, DETECTION, DT, gain=DT**2 / (DETECTION - D_MIN))
    q = arm.reset(q0)
    clearance, error = [], []
    for n in range(150):  # the approach sweeps the forearm past the bracket at 0.4-0.8 s
        q = arm.step(CIRCLE(n * DT))
        clearance.append(scene.min_distance(q))
        error.append(np.linalg.norm(scene.robot.ee_position(q) - CIRCLE(n * DT)))
    assert min(clearance) >= D_MIN - 1e-4
    assert max(error[-20:]) < 1e-4 and arm.infeasible == 0


@pytest.mark.slow
def test_peers_benchmark_prints_its_keys_as_one_json_object():
    m = benchmark("peers.py", "--steps", "50")
    keys = ["qp_step_us", "improved_step_us", "mink_step_us", "qp_vs_mink", "improved_vs_mink",
            "qp_per_far_obstacle_us", "improved_per_far_obstacle_us", "mink_per_far_obstacle_us",
            "qp_rms_m", "improved_rms_m", "mink_rms_m", "qp_min_clearance_m",
            "improved_min_clearance_m", "mink_min_clearance_m", "qp_per_near_obstacle_us",
            "improved_per_near_obstacle_us", "mink_per_near_obstacle_us"]  # fmt: skip
    for key in keys:
        assert np.isfinite(m[key]), key
    for name in ("qp", "improved", "mink"):
        assert m[f"{name}_step_us"] > 0
    assert m["qp_vs_mink"] == pytest.approx(m["qp_step_us"] / m["mink_step_us"])
    assert m["far_min_distance_m"] > m["detection_m"]
    # The near obstacles: within reach, outside the detection distance of every motion.
    assert m["detection_m"] < m["near_distance_m"][0] <= m["near_distance_m"][1] <= 0.6


@pytest.mark.slow
def test_clutter_benchmark_prints_its_keys_as_one_json_object():
    m = benchmark("clutter.py", "--steps", "40")
    assert m["obstacles"] == 50 and m["clutter_distance_m"] >= 0.2
    for name in ("qp", "improved", "mink"):
        assert m[f"{name}_clutter_ratio"] == pytest.approx(
            m[f"{name}_step_us_50"] / m[f"{name}_step_us_2"]
        )
        assert m[f"{name}_min_clearance_m_50"] > -0.01  # mink's default gain dips 2 mm in
