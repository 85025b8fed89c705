"""scene/gjk.py: the compiled GJK distance between posed, swept convex cores against closed forms
for two unit cubes."""

from __future__ import annotations

import numpy as np
import pytest

from articula.geometry.shapes import convex_hull
from articula.robots import RobotModel
from articula.scene import Obstacle, Scene
from articula.scene.compiled_clearance import CompiledClearance
from articula.scene.gjk import gjk_distance

ROBOT = RobotModel.builtin("iiwa14")


@pytest.fixture(scope="module")
def cube_distance():
    """cube_distance(offset, r1=0, r2=0): GJK distance [m] between two unit cubes (one core,
    posed twice, unrotated), the second `offset` [m] from the first, swept by r1 and r2 [m]."""
    corners = np.array(np.meshgrid([-0.5, 0.5], [-0.5, 0.5], [-0.5, 0.5])).reshape(3, -1).T
    part = Scene(ROBOT, [Obstacle("a", (convex_hull(corners),), np.eye(4))])
    c = CompiledClearance.build(part)
    k = len(ROBOT.links)  # the cube is the first shape after the links
    eye = np.eye(3)

    def distance(offset, r1: float = 0.0, r2: float = 0.0) -> float:
        args = (c.shapes.vertices, c.shapes.neighbours, c.shapes.offsets, c.scratch.hints.copy())
        return gjk_distance(*args, k, eye, np.zeros(3), r1, k, eye, np.asarray(offset, float),
                            r2, np.zeros(7, dtype=np.int64))  # fmt: skip

    return distance


def test_face_to_face_distance_of_unit_cubes(cube_distance):
    assert cube_distance([1.5, 0.0, 0.0]) == pytest.approx(0.5, abs=1e-12)


def test_corner_to_corner_distance_along_the_diagonal(cube_distance):
    # sqrt(3)·(s − 1) for centres s·(1,1,1) apart.
    assert cube_distance(np.full(3, 1.4)) == pytest.approx(np.sqrt(3) * 0.4, abs=1e-12)


def test_sweeping_radii_are_subtracted(cube_distance):
    # The same cubes swept by radii 0.1 and 0.2 lose 0.3.
    assert cube_distance([1.5, 0.0, 0.0], 0.1, 0.2) == pytest.approx(0.2, abs=1e-12)


def test_overlapping_cubes_are_at_distance_zero(cube_distance):
    assert cube_distance([0.9, 0.1, 0.0]) == 0.0


def test_a_cached_simplex_gives_the_cold_answer_along_a_path_through_contact():
    # Two cubes, one turning and sliding past the other through face, edge and corner
    # contacts and an overlap: GJK restarted from the last simplex (the planner's case)
    # answers as a cold start does; the cache holds edges and triangles on the way, 0 on overlap.
    corners = np.array(np.meshgrid([-0.5, 0.5], [-0.5, 0.5], [-0.5, 0.5])).reshape(3, -1).T
    c = CompiledClearance.build(Scene(ROBOT, [Obstacle("a", (convex_hull(corners),), np.eye(4))]))
    k = len(ROBOT.links)
    cache = np.zeros(7, dtype=np.int64)
    sizes = set()
    for s in np.linspace(0.0, 1.0, 200):
        angle = 1.5 * s
        R = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0],
                      [0.0, 0.0, 1.0]])  # fmt: skip
        p = np.array([1.6 - 0.8 * s, 0.9 * s, 0.3 * np.sin(5 * s)])
        shapes, hints = c.shapes, c.scratch.hints
        args = (shapes.vertices, shapes.neighbours, shapes.offsets, hints, k, np.eye(3),
                np.zeros(3), 0.0, k, R, p, 0.05)  # fmt: skip
        warm = gjk_distance(*args, cache)
        cold = gjk_distance(*args, np.zeros(7, dtype=np.int64))
        assert warm == pytest.approx(cold, abs=1e-12)
        sizes.add(int(cache[0]))
    assert sizes >= {0, 2, 3}
