"""scene/compiled_rows.py: the compiled end-effector kinematics and clearance rows against
Pinocchio and coal (planning.clearance.clearance_rows) on the book's two-obstacle scene with
self-collision checked, and their gradients against finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from articula.planning.clearance import clearance_rows as coal_rows
from articula.scene import Scene
from articula.scene.compiled_clearance import CompiledClearance
from articula.scene.compiled_rows import clearance_rows
from articula.scene.self_collision import self_collision_matrix
from tests.robots.helpers import central_differences
from tests.scene.helpers import book_scene

INFLUENCE = 0.15


@pytest.fixture(scope="module")
def scene() -> Scene:
    """circle_two_obstacles with the iiwa's self-collision pairs checked."""
    base = book_scene("circle_two_obstacles")
    pairs = self_collision_matrix(base.robot).checked
    return Scene(base.robot, base.obstacles, self_pairs=pairs)


@pytest.fixture(scope="module")
def configurations(scene: Scene) -> list[np.ndarray]:
    """40 seeded collision-free configurations with at least one row within the influence."""
    rng, robot, out = np.random.default_rng(3), scene.robot, []
    while len(out) < 40:
        q = rng.uniform(robot.lower, robot.upper)
        d_obstacle, d_self = scene.clearances(q)
        if min(d_obstacle, d_self) > 1e-3 and min(d_obstacle, d_self) < INFLUENCE:
            out.append(q)
    return out


def test_end_effector_pose_and_jacobian_are_pinocchios(scene, configurations):
    compiled = CompiledClearance.build(scene)
    for q in configurations:
        x, R, J, *_ = clearance_rows(compiled, q, INFLUENCE)
        pose = scene.robot.ee_pose(q)
        assert np.allclose(x, pose[:3, 3], atol=1e-12)
        assert np.allclose(R, pose[:3, :3], atol=1e-12)
        assert np.allclose(J, scene.robot.jacobian(q), atol=1e-12)


def test_rows_are_coals_to_gjk_tolerance(scene, configurations):
    compiled = CompiledClearance.build(scene)
    rows_seen = self_rows_seen = 0
    for q in configurations:
        _, _, _, distance, gradient, self_pair = clearance_rows(compiled, q, INFLUENCE)
        oracle = coal_rows(scene, q, 0.0, INFLUENCE)
        moving = np.any(oracle.gradient != 0.0, axis=1)
        assert np.array_equal(self_pair, oracle.self_pair[moving])
        assert np.allclose(distance, oracle.distance[moving], atol=1e-7)
        # coal stops GJK earlier: its witness points sit up to ~1e-5 m off (one row here by
        # 1.3e-5 in the gradient, where ours matches central differences to 1e-9).
        assert np.allclose(gradient, oracle.gradient[moving], atol=5e-5)
        rows_seen += distance.size
        self_rows_seen += int(self_pair.sum())
    assert rows_seen >= 40 and self_rows_seen >= 1  # both kinds were compared


def test_gradients_are_finite_differences_of_the_distances(scene, configurations):
    compiled = CompiledClearance.build(scene)

    def distances(q: np.ndarray) -> np.ndarray:
        return clearance_rows(compiled, q, np.inf)[3]

    for q in configurations[:10]:
        *_, gradient, _ = clearance_rows(compiled, q, np.inf)
        assert np.allclose(gradient, central_differences(distances, q, 1e-6), atol=1e-5)


def test_an_overlapping_pair_within_the_influence_asks_for_the_fallback(scene):
    compiled = CompiledClearance.build(scene)
    rng = np.random.default_rng(5)
    while True:
        q = rng.uniform(scene.robot.lower, scene.robot.upper)
        if scene.clearances(q)[0] <= 0.0:
            break
    assert clearance_rows(compiled, q, INFLUENCE) is None
