"""geometry/shapes.py: convex hulls of point clouds and the primitives, their vertices, bounds and
errors, against scipy and closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.errors import GeometryError
from articula.geometry.shapes import box, capsule, convex_hull, cylinder, sphere

# ----- convex_hull ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("points", "words"),
    [
        (np.zeros((0, 3)), ["cloud", "(0, 3)"]),
        (np.zeros((5, 2)), ["cloud", "(5, 2)"]),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), ["cloud", "flat"]),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.3, 0.2, 0]]), ["cloud", "flat"]),
        (np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3.0]]), ["cloud", "flat"]),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, np.nan]]), ["cloud", "NaN"]),
    ],
    ids=["empty", "2d", "three", "plane", "line", "nan"],
)
def test_convex_hull_rejects(points, words):
    with pytest.raises(GeometryError) as exc:
        convex_hull(points, "cloud")
    for word in words:
        assert word in str(exc.value)


def test_convex_hull_of_cube_with_interior_points():
    rng = np.random.default_rng(3)
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 3)], float)
    inner = rng.uniform([0, 0, 0], [1, 2, 3], size=(50, 3))
    shape = convex_hull(np.vstack([inner, corners]), "cube")
    assert shape.kind == "convex"
    assert sorted(map(tuple, shape.vertices)) == sorted(map(tuple, corners))
    assert shape.geometry.num_points == 8


# ----- primitives -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("make", "kind"),
    [
        (lambda: box((1.0, 0.0, 1.0)), "box"),
        (lambda: box((1.0, -1.0, 1.0)), "box"),
        (lambda: box((1.0, math.nan, 1.0)), "box"),
        (lambda: box((1.0, 1.0)), "box"),
        (lambda: sphere(0.0), "sphere"),
        (lambda: sphere(-0.1), "sphere"),
        (lambda: sphere(math.inf), "sphere"),
        (lambda: cylinder(0.1, 0.0), "cylinder"),
        (lambda: cylinder(-0.1, 1.0), "cylinder"),
        (lambda: capsule(0.0, 1.0), "capsule"),
        (lambda: capsule(0.1, -1.0), "capsule"),
        (lambda: capsule(0.1, math.nan), "capsule"),
    ],
)
def test_non_positive_primitive_sizes(make, kind):
    with pytest.raises(GeometryError) as exc:
        make()
    assert str(exc.value).startswith(f"{kind}:")
    assert "positive" in str(exc.value)


def test_box_corners_are_at_the_half_sizes():
    b = box((0.2, 0.4, 0.6))
    np.testing.assert_allclose(np.abs(b.vertices), np.tile([0.1, 0.2, 0.3], (8, 1)))


def test_sphere_vertices_lie_on_the_sphere():
    s = sphere(0.3)
    np.testing.assert_allclose(np.linalg.norm(s.vertices, axis=1), 0.3, rtol=1e-9)


def test_cylinder_vertices_lie_on_its_rims():
    c = cylinder(0.1, 0.5)
    np.testing.assert_allclose(np.abs(c.vertices[:, 2]), 0.25, rtol=1e-9)
    assert np.linalg.norm(c.vertices[:, :2], axis=1).max() == pytest.approx(0.1)


def test_capsule_vertices_are_one_radius_from_the_core_segment():
    k = capsule(0.1, 0.5)
    # Distance of each tessellation vertex from the core segment is the radius.
    along = np.clip(k.vertices[:, 2], -0.25, 0.25)
    gap = np.linalg.norm(k.vertices - np.c_[np.zeros((len(along), 2)), along], axis=1)
    np.testing.assert_allclose(gap, 0.1, rtol=1e-9)
    assert k.vertices[:, 2].max() == pytest.approx(0.35)


@pytest.mark.parametrize(
    ("shape", "radius", "length"),
    [(sphere(0.3), 0.3, 0.0), (cylinder(0.1, 0.5), 0.1, 0.5), (capsule(0.1, 0.5), 0.1, 0.5)],
    ids=["sphere", "cylinder", "capsule"],
)
def test_round_primitive_bounds_contain_the_solid_not_only_its_tessellation(shape, radius, length):
    assert shape.bound.radius >= radius and shape.bound.length >= length - 1e-12
    np.testing.assert_allclose(shape.bound.pose, np.eye(4))
