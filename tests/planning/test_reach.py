"""planning/reach.py: the reach sphere of a revolute chain, by hand for the iiwa14, and the refusal
of a path that leaves it, naming the trajectory."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import InfeasibleError
from articula.geometry.shapes import sphere
from articula.planning.reach import check_reach, reach_sphere
from articula.planning.trajectories import Circle
from tests.planning.helpers import CIRCLE, ROBOT
from tests.scene.helpers import one_link_robot


def test_iiwa_reach_sphere_is_centred_on_joint_1_and_spans_the_stretched_arm():
    # Joint 1's origin is 0.1575 m up; stretched, the flange is 1.306 m up (the joint table).
    centre, radius = reach_sphere(ROBOT)
    np.testing.assert_allclose(centre, [0.0, 0.0, 0.1575], atol=1e-12)
    assert radius == pytest.approx(1.306 - 0.1575, abs=1e-12)


def test_an_axis_aligned_prismatic_joint_has_no_reach_sphere():
    # Pinocchio names an axis-aligned slide JointModelPX/PY/PZ, not "...Prismatic...".
    slider = one_link_robot([sphere(0.1)], [np.eye(4)])  # a slide along z in [-1, 1] m
    assert reach_sphere(slider) is None
    check_reach(slider, lambda t: np.array([0.0, 0.0, 0.5]), 1.0)  # reachable by sliding


def test_a_path_out_of_reach_is_refused_naming_the_trajectory():
    far = Circle.create([2.0, 0.0, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)
    with pytest.raises(InfeasibleError, match="reach") as exc:
        check_reach(ROBOT, far, 50.0)
    assert exc.value.field == "trajectory"
    assert str(exc.value).startswith("trajectory: unreachable")


def test_the_book_circle_is_within_reach():
    check_reach(ROBOT, CIRCLE, 50.0)
