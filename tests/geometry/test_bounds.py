"""geometry/bounds.py: bounding capsules contain their points, and are tight on simple shapes."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from articula.geometry.bounds import bounding_capsule
from articula.geometry.shapes import box


def _segment_distance(points: np.ndarray, T: np.ndarray, length: float) -> np.ndarray:
    a = T[:3, 3] - 0.5 * length * T[:3, 2]
    axis = T[:3, 2]
    t = np.clip((points - a) @ axis, 0.0, length)
    return np.linalg.norm(points - (a + t[:, None] * axis), axis=1)


clouds = st.integers(4, 30).flatmap(
    lambda n: arrays(np.float64, (n, 3), elements=st.floats(-1.0, 1.0, allow_subnormal=False))
)


@settings(max_examples=60, deadline=None)
@given(points=clouds, stretch=st.sampled_from([1.0, 0.1, 5.0]))
def test_bounding_capsule_contains_every_point(points, stretch):
    pts = points * [stretch, 1.0, 1.0]
    cap = bounding_capsule(pts)
    R = cap.pose[:3, :3]
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-9)
    assert np.linalg.det(R) == pytest.approx(1.0)
    assert cap.radius >= 0.0 and cap.length >= 0.0
    assert np.all(_segment_distance(pts, cap.pose, cap.length) <= cap.radius + 1e-12)


def test_bounding_capsule_of_a_long_box_is_tight():
    cap = bounding_capsule(box((1.0, 0.1, 0.1)).vertices)
    assert cap.radius == pytest.approx(math.hypot(0.05, 0.05), rel=1e-6)
    assert cap.length == pytest.approx(1.0, rel=1e-6)
    assert abs(cap.pose[:3, 2] @ [1.0, 0.0, 0.0]) == pytest.approx(1.0)


def test_bounding_capsule_of_points_on_a_sphere_is_a_sphere():
    pts = np.asarray(trimesh.creation.icosphere(subdivisions=3, radius=0.2).vertices)
    pts = pts + np.array([1.0, 2.0, 3.0])
    cap = bounding_capsule(pts)
    assert cap.length == pytest.approx(0.0, abs=1e-6)
    assert cap.radius == pytest.approx(0.2, rel=1e-3)
    np.testing.assert_allclose(cap.pose[:3, 3], [1.0, 2.0, 3.0], atol=1e-6)
