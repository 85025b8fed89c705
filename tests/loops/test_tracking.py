"""loops/tracking.py: track() refuses bad arguments and starts naming the argument, and records
one sample per period; tracking_metrics and trace_columns of a run written out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.loops.tracking import PlanResult, trace_columns, track, tracking_metrics
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.objective import Objective
from articula.planning.velocity_ik import VelocityIk
from tests.planning.helpers import CIRCLE, DT, FREE, ROBOT, ball


@pytest.mark.parametrize(
    ("center", "d_min", "words"),
    [
        ([0.0, 0.0, 1.0], 0.002, "collides"),  # the stretched arm passes through the ball
        ([0.3, 0.0, 1.0], 0.2, "d_min"),  # 0.132 m from the stretched arm
    ],
    ids=["collision", "within_d_min"],
)
def test_a_start_too_close_to_an_obstacle_is_refused_naming_q0(center, d_min, words):
    objective = Objective(ball(center, 0.1), 0.001, d_min=d_min)
    planner = Baornn(objective, BaornnParams(), np.random.default_rng(0))
    with pytest.raises(InfeasibleError, match=words) as exc:
        track(planner, CIRCLE, np.zeros(7), 0.01, 0.1)
    assert exc.value.field == "q0"


def test_a_start_beyond_the_joint_limits_is_refused_naming_q0():
    q0 = ROBOT.upper + 0.1
    with pytest.raises(InfeasibleError, match="joint limits") as exc:
        track(VelocityIk(FREE, "pinv", DT), CIRCLE, q0, DT, 0.1)
    assert exc.value.field == "q0"


def test_a_start_of_the_wrong_size_is_refused_naming_q0():
    with pytest.raises(ConfigError) as exc:
        track(VelocityIk(FREE, "pinv", DT), CIRCLE, np.zeros(6), DT, 0.1)
    assert exc.value.field == "q0"


@pytest.mark.parametrize(
    ("dt", "duration", "field"),
    [
        (0.0, 1.0, "dt"),
        (math.nan, 1.0, "dt"),
        (0.01, 0.005, "duration"),
        (0.01, math.inf, "duration"),
    ],
)
def test_bad_times_name_the_argument(dt, duration, field):
    with pytest.raises(ConfigError) as exc:
        track(VelocityIk(FREE, "pinv", DT), CIRCLE, np.zeros(7), dt, duration)
    assert exc.value.field == field


def test_track_records_one_sample_per_period():
    run = track(VelocityIk(FREE, "pinv", DT), CIRCLE, np.zeros(7), DT, 0.2)
    np.testing.assert_allclose(run.t, np.arange(20) * DT)
    assert run.q.shape == (20, 7) and run.x.shape == run.x_ref.shape == (20, 3)
    np.testing.assert_allclose(run.x_ref, [CIRCLE(t) for t in run.t])
    np.testing.assert_allclose(run.x, [ROBOT.ee_position(q) for q in run.q])
    np.testing.assert_allclose(run.error, np.linalg.norm(run.x - run.x_ref, axis=1))
    assert np.all(run.clearance == np.inf)  # no obstacle, nothing measured
    assert run.planner_seconds > 0


def _hand_run() -> PlanResult:
    """Four periods of 0.5 s: errors 4, 3, 1, 1 cm; the second sample collides and the last one
    breaks joint 1's upper limit."""
    q = np.zeros((4, 7))
    q[3, 0] = ROBOT.upper[0] + 0.1
    x = np.zeros((4, 3))
    x_ref = np.array([[0.04, 0, 0], [0, 0.03, 0], [0, 0, 0.01], [0.01, 0, 0]])
    error = np.linalg.norm(x - x_ref, axis=1)
    clearance = np.array([0.2, -0.01, 0.05, 0.1])
    return PlanResult(np.arange(4) * 0.5, q, x, x_ref, error, clearance, planner_seconds=0.002)


def test_tracking_metrics_by_hand():
    m = tracking_metrics(_hand_run(), ROBOT, settle=1.0, iterations=40)
    assert m["settle_s"] == 1.0
    assert m["rms_error"] == pytest.approx(0.01)  # the last two samples
    assert m["max_error"] == pytest.approx(0.01)
    assert m["min_clearance"] == -0.01 and m["min_clearance_settled"] == 0.05
    assert m["collisions"] == 1 and m["collisions_settled"] == 0
    assert m["joint_limit_violations"] == 1
    # 2 ms over the 3 periods after the first, 10 iterations each.
    assert m["time_per_iteration_us"] == pytest.approx(2000.0 / 30)
    assert m["time_per_period_us"] == pytest.approx(2000.0 / 3)
    assert m["first_period_ms"] == 0.0


def test_trace_columns_name_each_series():
    run = _hand_run()
    columns = trace_columns(run)
    assert list(columns) == ["t", "phase", *(f"q_{j}" for j in range(1, 8)), "x", "y", "z",
                             "x_ref", "y_ref", "z_ref", "error", "clearance"]  # fmt: skip
    assert set(columns["phase"]) == {"path"}  # no approach
    np.testing.assert_array_equal(columns["q_1"], run.q[:, 0])
    np.testing.assert_array_equal(columns["y_ref"], run.x_ref[:, 1])
    np.testing.assert_array_equal(columns["clearance"], run.clearance)


def test_acceleration_use_of_runs_written_out_by_hand():
    # From rest at q0 = 0, joint 1 at constant acceleration 0.5 of its limit for 10 periods,
    # then joint 2 bang-bang at its full limit for 10: second differences by hand.
    dt, n = 0.01, 20
    limit = ROBOT.acceleration_limit
    k = np.arange(1, n + 1)
    q = np.zeros((n, ROBOT.nq))
    q[:10, 0] = 0.5 * limit[0] * 0.5 * (k[:10] * dt) ** 2 + 0.5 * 0.5 * limit[0] * k[:10] * dt**2
    # 2nd difference of a·(k² + k)/2·dt² is a·dt²: a constant 0.5 of the limit.
    q[10:, 0] = q[9, 0] + (q[9, 0] - q[8, 0]) * np.arange(1, 11)  # coasting: no acceleration
    bang = np.cumsum(np.cumsum(np.where(np.arange(10) % 2 == 0, 1.0, -1.0))) * limit[1] * dt**2
    q[10:, 1] = bang
    t = np.arange(n) * dt
    x = np.zeros((n, 3))
    run = PlanResult(t, q, x, x, np.zeros(n), np.full(n, 1.0), planner_seconds=0.0, q0=np.zeros(7))
    first = tracking_metrics(run, ROBOT, settle=0.0, iterations=1)
    ratio = np.abs(np.diff(np.vstack([np.zeros((2, 7)), q]), 2, axis=0)) / (dt**2 * limit)
    assert ratio[:10, 0] == pytest.approx(np.full(10, 0.5))  # the hand-made motion
    assert first["accel_rms_ratio"] == pytest.approx(np.sqrt(np.mean(ratio**2)))
    # Periods 10..19 have joint 2 at its full limit (and the start of the coast is no jump).
    assert first["saturated_fraction"] == pytest.approx(np.mean(np.any(ratio >= 0.9, axis=1)))
    assert 0.4 <= first["saturated_fraction"] <= 0.6
    settled = tracking_metrics(run, ROBOT, settle=0.095, iterations=1)  # the last 10 periods
    assert settled["saturated_fraction"] == 1.0
    assert settled["accel_rms_ratio"] == pytest.approx(np.sqrt(np.mean(ratio[10:] ** 2)))
