"""planning/rate_limits.py: the box one period's joint speeds and accelerations allow."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.loops.tracking import max_speed_ratio, track
from articula.planning.config import PlannerSpec, make_planner
from articula.planning.rate_limits import RateLimits
from tests.planning.helpers import CIRCLE, DT, ROBOT, ball

LOWER, UPPER = -np.ones(2), np.ones(2)


def test_the_box_is_the_speed_reach_inside_the_joint_limits():
    rate = RateLimits(np.array([1.0, 2.0]), dt=0.1)
    low, high = rate.box(np.array([0.0, 0.95]), LOWER, UPPER)
    np.testing.assert_allclose(low, [-0.1, 0.75])
    np.testing.assert_allclose(high, [0.1, 1.0])  # the joint limit is nearer than the reach


def test_the_acceleration_limit_keeps_the_next_motion_near_the_last():
    rate = RateLimits(np.array([10.0, 10.0]), dt=0.1, acceleration=2.0)
    rate.record(np.array([0.5, 0.0]))
    low, high = rate.box(np.zeros(2), 10 * LOWER, 10 * UPPER)
    np.testing.assert_allclose(low, [0.48, -0.02])
    np.testing.assert_allclose(high, [0.52, 0.02])
    rate.reset()
    np.testing.assert_allclose(rate.box(np.zeros(2), 10 * LOWER, 10 * UPPER)[1], [1.0, 1.0])


@pytest.mark.parametrize("fields", [{"velocity": [0.0, 1.0]}, {"dt": 0.0}, {"acceleration": -1.0}])
def test_bad_limits_name_the_field(fields):
    with pytest.raises(ConfigError):
        RateLimits(**{"velocity": [1.0, 1.0], "dt": 0.1, **fields})


@pytest.mark.parametrize("method", ["baornn", "baornn-improved"])
def test_beetle_planners_keep_the_urdf_speed_limits_unless_told_not_to(method):
    scene = ball([0.4, 0.3, 0.6], 0.05)
    q0 = np.zeros(ROBOT.nq)
    ratios = {}
    for limits in ("velocity", "none"):
        spec = PlannerSpec(method=method, lambda_weight=0.002, d_min=0.002, c1=0.3,
                           duration=1.0, settle=0.5, limits=limits)  # fmt: skip
        run = track(make_planner(spec, scene, seed=0), CIRCLE, q0, DT, spec.duration)
        ratios[limits] = max_speed_ratio(run, ROBOT)
    assert ratios["velocity"] <= 1.0 + 1e-9
    assert ratios["none"] > 1.0  # the book's Algorithm 1 knows no speed limit


def test_the_velocity_scale_scales_the_limit():
    spec = PlannerSpec(method="baornn", c1=0.3, duration=0.5, settle=0.2, velocity_scale=0.5)
    run = track(make_planner(spec, ball([0.4, 0.3, 0.6], 0.05), 0), CIRCLE, np.zeros(7), DT, 0.5)
    assert max_speed_ratio(run, ROBOT) <= 0.5 + 1e-9
