"""planning/approach.py: the reference from the tool to the path's start, then the path."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from articula.planning.approach import NEAR, PEAK, approach
from articula.planning.task import Target
from articula.planning.trajectories import Circle

CIRCLE = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)
TOOL = np.array([0.0, 0.0, 1.3])


def test_the_approach_starts_at_the_tool_and_ends_at_rest_on_the_path():
    reference = approach(CIRCLE, Target(TOOL), speed=0.25, turn_rate=0.5)
    distance = np.linalg.norm(CIRCLE(0.0) - TOOL)
    assert reference.duration == pytest.approx(PEAK * distance / 0.25)
    np.testing.assert_allclose(reference(0.0).position, TOOL, atol=1e-12)
    T = reference.duration
    np.testing.assert_allclose(reference(T).position, CIRCLE(0.0), atol=1e-12)
    np.testing.assert_allclose(reference(T + 3.0).position, CIRCLE(3.0), atol=1e-12)
    # Along a straight line, at most `speed`, at rest at both ends (minimum jerk).
    t = np.linspace(0.0, T, 2001)
    x = np.array([reference(s).position for s in t])
    v = np.linalg.norm(np.diff(x, axis=0), axis=1) / (t[1] - t[0])
    assert v.max() <= 0.25 * (1 + 1e-3) and v[0] < 1e-3 and v[-1] < 1e-3
    off_line = np.cross(x - TOOL, CIRCLE(0.0) - TOOL)
    assert np.abs(off_line).max() < 1e-12


def test_a_path_that_starts_at_the_tool_needs_no_approach():
    near = CIRCLE(0.0) + np.array([0.5 * NEAR, 0.0, 0.0])
    assert approach(CIRCLE, Target(near), 0.25, 0.5).duration == 0.0


def test_the_orientation_turns_by_slerp_at_the_turn_rate():
    turned = Rotation.from_rotvec([0.0, 0.0, 1.2]).as_matrix()

    def pose_path(t: float) -> Target:
        return Target(CIRCLE(t), turned)

    start = Target(CIRCLE(0.0), np.eye(3))
    reference = approach(pose_path, start, speed=0.25, turn_rate=0.5)
    assert reference.duration == pytest.approx(PEAK * 1.2 / 0.5)
    half = reference(0.5 * reference.duration).rotation
    assert Rotation.from_matrix(half).magnitude() == pytest.approx(0.6, abs=1e-9)


def test_a_tool_axis_turns_toward_the_paths():
    def axis_path(t: float) -> Target:
        return Target(CIRCLE(t), None, np.array([0.0, 0.0, -1.0]))

    start = Target(CIRCLE(0.0), None, np.array([1.0, 0.0, 0.0]))
    reference = approach(axis_path, start, speed=0.25, turn_rate=0.5)
    assert reference.duration == pytest.approx(PEAK * (np.pi / 2) / 0.5)
    for u in (0.0, 0.3, 0.7, 1.0):
        axis = reference(u * reference.duration).axis
        assert np.linalg.norm(axis) == pytest.approx(1.0)
        assert axis[1] == pytest.approx(0.0, abs=1e-12)  # in the plane of the two
