"""scene/obstacles.py: an obstacle's parts and pose are checked when built (a pose function when it
is evaluated), and a pose function moves the obstacle through the scene's distances."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from articula.errors import GeometryError
from articula.geometry.shapes import box, sphere
from articula.scene import Obstacle, Scene
from tests.scene.helpers import box_signed_distance, one_link_robot, rigid

PART = (sphere(0.1),)
MIRRORED = np.diag([1.0, 1.0, -1.0, 1.0])


def test_obstacle_without_parts_is_refused_by_name():
    with pytest.raises(GeometryError, match="'empty'"):
        Obstacle("empty", (), np.eye(4))


@pytest.mark.parametrize("T", [np.eye(3), np.full((4, 4), np.nan)], ids=["3x3", "nan"])
def test_pose_must_be_a_finite_4x4_matrix(T):
    with pytest.raises(GeometryError, match="4×4"):
        Obstacle("bad", PART, T)


def _skew() -> np.ndarray:
    skew = np.eye(4)
    skew[0, 1] = 0.5
    return skew


@pytest.mark.parametrize("T", [MIRRORED, _skew()], ids=["mirror", "skew"])
def test_pose_must_hold_a_rotation(T):
    with pytest.raises(GeometryError, match="rotation"):
        Obstacle("bad", PART, T)


def test_a_pose_function_is_checked_when_it_is_evaluated():
    drifting = Obstacle("drift", PART, lambda t: MIRRORED if t > 1 else np.eye(4))
    scene = Scene(one_link_robot([sphere(0.1)], [np.eye(4)]), [drifting])
    scene.distances([0.0], 0.5)
    with pytest.raises(GeometryError, match="'drift'"):
        scene.distances([0.0], 2.0)


def test_obstacle_with_a_pose_function():
    radius = 0.5

    def orbit(t: float) -> np.ndarray:
        return rigid(Rotation.from_euler("z", t).as_matrix(), [radius * math.cos(t), 0.0, 0.0])

    robot = one_link_robot([sphere(0.1)], [rigid(np.eye(3), [0.5, 0.0, 0.0])])
    obstacle = Obstacle("moon", (box((0.1, 0.1, 0.1)),), orbit)
    assert obstacle.moving
    scene = Scene(robot, [obstacle])
    for t in (0.0, 0.5, 1.0, math.pi / 2, 3.0):
        centre = np.array([radius * math.cos(t), 0.0, 0.0])
        local = orbit(t)[:3, :3].T @ (np.array([0.5, 0.0, 0.0]) - centre)
        expected = box_signed_distance(local, np.full(3, 0.05)) - 0.1
        assert scene.distances([0.0], t)[0, 0] == pytest.approx(expected, abs=1e-7), t
    assert scene.min_distance([0.0], 0.0) < 0  # the box sits inside the sphere at t = 0
