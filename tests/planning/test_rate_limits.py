"""planning/rate_limits.py: the box one period's joint speeds and accelerations allow."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

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
    low, high = rate.box(np.zeros(2), 100 * LOWER, 100 * UPPER)
    np.testing.assert_allclose(low, [0.48, -0.02])
    np.testing.assert_allclose(high, [0.52, 0.02])
    rate.reset()  # at rest: the first motion is an acceleration from zero
    np.testing.assert_allclose(rate.box(np.zeros(2), 100 * LOWER, 100 * UPPER)[1], [0.02, 0.02])
    assert not rate.strained


def test_each_joint_has_its_own_acceleration_limit():
    rate = RateLimits(np.array([10.0, 10.0]), dt=0.1, acceleration=np.array([1.0, 3.0]))
    np.testing.assert_allclose(rate.box(np.zeros(2), 100 * LOWER, 100 * UPPER)[1], [0.01, 0.03])
    np.testing.assert_allclose(rate.change, [0.01, 0.03], rtol=1e-8)


def test_a_joint_brakes_in_time_for_its_position_limit():
    # At 1 rad/s toward a limit 0.3 rad away with 2 rad/s²: braking needs 0.25 rad, so the
    # next motion toward it must leave room to stop: m + m²/(2c) ≤ 0.3 - ..., c = 0.02 rad.
    rate = RateLimits(np.array([10.0]), dt=0.1, acceleration=2.0)
    rate.record(np.array([0.1]))
    high = rate.box(np.array([0.7]), np.array([-1.0]), np.array([1.0]))[1]
    m = high[0] - 0.7
    assert m + m**2 / (2 * 0.02) <= 0.3 + 1e-12
    assert m >= 0.1 - 0.02 - 1e-12  # and it can still brake within the acceleration limit


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.floats(0.0, 1.0), min_size=1, max_size=150),
    st.floats(0.2, 5.0),
    st.one_of(st.none(), st.floats(1.0, 8.0)),
    st.floats(0.3, 0.99),
)
def test_any_motion_inside_each_box_keeps_every_limit(choices, acceleration, ramp_periods, start):
    """Whatever point of each period's box is taken, the motion never leaves the position
    limits, never breaks the speed or acceleration limit or, with one (the acceleration reached
    from zero in `ramp_periods` periods), the jerk limit, and the box is never empty, even
    driving into a position limit or up to the speed limit."""
    speed, dt = 1.5, 0.05
    jerk = None if ramp_periods is None else acceleration / (ramp_periods * dt)
    rate = RateLimits(np.array([speed]), dt=dt, acceleration=acceleration, jerk=jerk)
    q, last, last_change = np.array([start]), np.zeros(1), np.zeros(1)
    for u in choices:
        low, high = rate.box(q, LOWER, UPPER)
        assert not rate.strained
        q_next = low + u * (high - low)
        motion = q_next - q
        assert LOWER[0] - 1e-12 <= q_next[0] <= UPPER[0] + 1e-12
        assert abs(motion[0]) <= speed * dt * (1 + 1e-9)
        assert abs(motion[0] - last[0]) <= acceleration * dt**2 * (1 + 1e-9)
        change = motion - last
        if jerk is not None:
            assert abs(change[0] - last_change[0]) <= jerk * dt**3 * (1 + 1e-6)
        rate.record(motion)
        q, last, last_change = q_next, motion, change


@pytest.mark.parametrize("ramp_periods", [1.0, 4.0])
def test_driving_into_a_position_limit_at_full_speed_stops_at_it(ramp_periods):
    """Always taking the box's far end toward the upper limit: full speed, then a braking
    whose deceleration ramps up in time, ending at the limit without a strained period."""
    speed, dt, acceleration = 1.0, 0.01, 5.0
    rate = RateLimits(np.array([speed]), dt, acceleration, acceleration / (ramp_periods * dt))
    q = np.array([-1.0])
    for _ in range(1000):
        q_next = rate.box(q, LOWER, UPPER)[1]
        assert not rate.strained and q_next[0] <= UPPER[0] + 1e-12
        rate.record(q_next - q)
        q = q_next
    assert q[0] > UPPER[0] - 1e-3  # it got there


def test_a_motion_beyond_the_limits_strains_the_box_to_its_nearest_point():
    rate = RateLimits(np.array([1.0]), dt=0.1, acceleration=1.0)
    rate.record(np.array([0.5]))  # measured five times faster than the speed limit allows
    low, high = rate.box(np.zeros(1), LOWER, UPPER)
    assert rate.strained
    np.testing.assert_allclose([low[0], high[0]], [0.1, 0.1], rtol=1e-8)


@pytest.mark.parametrize(
    "fields",
    [{"velocity": [0.0, 1.0]}, {"dt": 0.0}, {"acceleration": -1.0}, {"jerk": 1.0},
     {"acceleration": 1.0, "jerk": 0.0}],
)  # fmt: skip
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
