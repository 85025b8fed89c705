"""loops/servo.py: the servo stream keeps every limit by differences of its samples, passes
each set-point LAG_PERIODS later, and is the exact line a steady motion's set-points lie on."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError, ModelError
from articula.loops.servo import LAG_PERIODS, ServoLimits, ServoStream, servo_trace
from articula.planning.rate_limits import RateLimits

DT = 0.01
N = 3
LIMITS = ServoLimits(
    lower=-np.full(N, 2.0),
    upper=np.full(N, 2.0),
    velocity=np.array([1.0, 1.5, 2.0]),
    acceleration=np.array([4.0, 6.0, 8.0]),
    jerk=np.array([400.0, 600.0, 800.0]),
)


def _within(trace, limits: ServoLimits, tolerance: float = 1e-6) -> None:
    """Speed, acceleration and jerk by differences of the streamed positions, and positions,
    within the limits."""
    h = trace.t[1] - trace.t[0]
    for order, limit in enumerate((limits.velocity, limits.acceleration, limits.jerk), start=1):
        rate = np.abs(np.diff(trace.q, order, axis=0)) / h**order
        assert np.all(rate <= limit * (1 + tolerance)), order
    assert np.all(trace.q >= limits.lower - 1e-12) and np.all(trace.q <= limits.upper + 1e-12)


def test_a_steady_motion_streams_as_the_exact_line_two_periods_behind():
    """Set-points on a line q(t) = q0 + v (t + dt), after a start within the limits: once the
    start's curve is over, the stream is the line itself, LAG_PERIODS late, at every tick."""
    v = np.array([0.3, -0.2, 0.1])  # [rad/s]
    rate = RateLimits(LIMITS.velocity, DT, LIMITS.acceleration, LIMITS.jerk)
    q, setpoints = np.zeros(N), []
    for _ in range(300):  # reach v from rest within the limits, then hold it
        low, high = rate.box(q, LIMITS.lower, LIMITS.upper)
        q_next = np.clip(q + v * DT, low, high)
        rate.record(q_next - q)
        setpoints.append(q_next)
        q = q_next
    setpoints = np.array(setpoints)
    trace = servo_trace(setpoints, np.zeros(N), DT, ServoStream(LIMITS, DT, 1000))
    assert trace.clipped == 0
    steady = np.nonzero(np.all(np.abs(np.diff(setpoints, axis=0) - v * DT) < 1e-15, axis=1))[0]
    first = steady[0] + 1  # the first set-point of the line's: s_k = s_first + v (k − first) dt
    # A period's segment needs four control points on the line: from (first + 3) dt on, the
    # stream at τ is the line at τ − LAG_PERIODS · dt (set-point k is commanded at k dt).
    # ... until the segment that takes the first braking point after the last set-point.
    on_line = (trace.t >= (first + 3) * DT - 1e-12) & (trace.t <= len(setpoints) * DT + 1e-12)
    tau = trace.t[on_line]
    line = setpoints[first] + np.outer(tau - (LAG_PERIODS + first) * DT, v)
    np.testing.assert_allclose(trace.q[on_line], line, atol=1e-12)
    np.testing.assert_allclose(trace.qd[on_line], np.tile(v, (tau.size, 1)), atol=1e-9)
    assert np.max(trace.deviation[first:-1]) < 1e-12
    assert np.max(np.abs(trace.qd[-1])) == 0 and np.max(np.abs(trace.qdd[-1])) == 0  # at rest
    _within(trace, LIMITS)


def test_set_points_that_break_every_limit_still_stream_within_them():
    """Random jumps far beyond the speed limit: the guard replaces them by the nearest control
    points that keep the limits, and counts them."""
    rng = np.random.default_rng(0)
    setpoints = rng.uniform(-3.0, 3.0, size=(200, N))
    stream = ServoStream(LIMITS, DT, 500)
    trace = servo_trace(setpoints, np.zeros(N), DT, stream)
    assert trace.clipped > 100
    _within(trace, LIMITS)
    assert np.max(np.abs(trace.qd[-1])) < 1e-9  # it still comes to rest
    assert trace.t[1] == pytest.approx(1 / 500)


def test_set_points_within_the_limits_are_passed_within_a_sixth_of_a_period_change():
    """Set-points from a sinusoid that keeps the discrete limits: never clipped, and the stream
    passes each within (its second difference) / 6 ≤ a dt² / 6, LAG_PERIODS later (the last
    one's second difference is the braking that follows it)."""
    t = np.arange(1, 400) * DT
    amplitude = np.array([0.2, 0.3, 0.1])
    setpoints = amplitude * (1 - np.cos(2.0 * t[:, None]))  # from rest at 0
    trace = servo_trace(setpoints, np.zeros(N), DT, ServoStream(LIMITS, DT, 1000))
    assert trace.clipped == 0
    bound = np.max(np.abs(np.diff(np.vstack([np.zeros((2, N)), setpoints]), 2, axis=0))) / 6
    assert np.max(trace.deviation[:-1]) <= bound + 1e-15
    assert np.max(trace.deviation) <= np.max(LIMITS.acceleration) * DT**2 / 6 * (1 + 1e-9)
    _within(trace, LIMITS)


def test_a_rate_that_is_not_a_whole_number_of_ticks_names_servo_rate():
    with pytest.raises(ConfigError, match=r"servo\.rate"):
        ServoStream(LIMITS, DT, 333.0)


def test_a_stream_before_its_reset_is_an_error():
    with pytest.raises(ModelError, match="reset"):
        ServoStream(LIMITS, DT, 1000).period(np.zeros(N))


def test_limits_without_a_finite_jerk_name_robot_jerk_limits():
    with pytest.raises(ConfigError, match=r"robot\.jerk_limits"):
        ServoLimits(LIMITS.lower, LIMITS.upper, LIMITS.velocity, LIMITS.acceleration,
                    np.array([1.0, np.inf, 1.0]))  # fmt: skip
