"""geometry/poses.py: roll-pitch-yaw rotations and homogeneous poses, against scipy and numpy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from articula.errors import GeometryError
from articula.geometry.poses import pose, rotation_rpy, transform_points

angles = st.floats(-math.pi, math.pi, allow_subnormal=False)


@settings(max_examples=50, deadline=None)
@given(r=angles, p=angles, y=angles)
def test_rotation_rpy_is_extrinsic_xyz(r, p, y):
    expected = Rotation.from_euler("xyz", [r, p, y]).as_matrix()
    np.testing.assert_allclose(rotation_rpy((r, p, y)), expected, atol=1e-12)


def test_pose_is_homogeneous_with_the_given_translation():
    T = pose((1.0, 2.0, 3.0), (0.0, 0.0, math.pi / 2))
    np.testing.assert_allclose(T[:3, 3], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(T[3], [0, 0, 0, 1])


def test_transform_points_rotates_then_translates():
    T = pose((1.0, 2.0, 3.0), (0.0, 0.0, math.pi / 2))
    pts = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(
        transform_points(T, pts), [[1.0, 3.0, 3.0], [0.0, 2.0, 3.0], [1.0, 2.0, 4.0]], atol=1e-12
    )


def test_transform_points_equals_the_homogeneous_product():
    rng = np.random.default_rng(0)
    T = pose(rng.normal(size=3), rng.normal(size=3))
    pts = rng.normal(size=(5, 3))
    homogeneous = np.c_[pts, np.ones(5)] @ T.T
    np.testing.assert_allclose(transform_points(T, pts), homogeneous[:, :3], atol=1e-12)


def test_pose_defaults_to_the_identity():
    np.testing.assert_array_equal(pose(), np.eye(4))


@pytest.mark.parametrize(
    ("position", "rpy"),
    [((0, 0), (0, 0, 0)), ((0, 0, 0), (0, 0, 0, 0)), ((0, math.nan, 0), (0, 0, 0)),
     ((0, 0, 0), (0, math.inf, 0))],
)  # fmt: skip
def test_pose_rejects_bad_input(position, rpy):
    with pytest.raises(GeometryError, match="pose"):
        pose(position, rpy)
