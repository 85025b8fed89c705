"""control/pid.py: the discrete PID of Eqs. (2.2)-(2.4): hand-computed sequences, anti-windup,
gain schedules."""

import numpy as np
import pytest

from articula.control.pid import PID, GainSchedule
from articula.errors import ConfigError

ROWS = np.array([[1.0, 2.0, 0.0], [3.0, 4.0, 0.5], [5.0, 6.0, 1.0]])
POINTS = np.array([15.0, 45.0, 75.0])


def _constant(kp: float, ki: float, kd: float) -> GainSchedule:
    return GainSchedule("constant", np.array([[kp, ki, kd]]))


def test_hand_computed_sequence_with_uneven_sample_times():
    # K = [2, 0.5, 0.1], θ_r = 1, θ = 0, 0.5, 0.8, 1.2 at t = 0, 0.1, 0.3, 0.35:
    # n0: e=1, no previous sample: u = 2
    # n1: e=0.5, Δt=0.1, Σ=0.05, Δe/Δt=-5: u = 1 + 0.025 - 0.5 = 0.525
    # n2: e=0.2, Δt=0.2, Σ=0.09, Δe/Δt=-1.5: u = 0.4 + 0.045 - 0.15 = 0.295
    # n3: e=-0.2, Δt=0.05, Σ=0.08, Δe/Δt=-8: u = -0.4 + 0.04 - 0.8 = -1.16
    TIMES, OUTPUTS = [0, 0.1, 0.3, 0.35], [0, 0.5, 0.8, 1.2]
    pid = PID(_constant(2.0, 0.5, 0.1))
    out = [pid(t, 1.0, np.array([y]))[0] for t, y in zip(TIMES, OUTPUTS, strict=True)]
    assert out == pytest.approx([2.0, 0.525, 0.295, -1.16])
    assert pid.integral[0] == pytest.approx(0.08)


def test_batch_rows_are_independent_controllers():
    pid = PID(_constant(2.0, 0.5, 0.1), trials=2)
    a = pid(0.0, 1.0, np.array([0.0, 0.3]))
    b = pid(0.1, 1.0, np.array([0.5, 0.3]))
    single = PID(_constant(2.0, 0.5, 0.1))
    assert [single(0.0, 1.0, np.array([0.3]))[0], single(0.1, 1.0, np.array([0.3]))[0]] == [
        a[1],
        b[1],
    ]
    assert b[0] == pytest.approx(0.525)


def test_anti_windup_holds_the_sum_while_saturated():
    # K_i = 1, limits [0, 1], Δt = 1: Σ reaches 1 (u = 1, not beyond), then would reach 2 and
    # is held at 1; an error of -1 then brings u straight to 0 (no wound-up sum to unwind).
    pid = PID(_constant(0.0, 1.0, 0.0), output_limits=(0.0, 1.0))
    out = [pid(float(t), r, np.array([0.0]))[0] for t, r in enumerate([1, 1, 1, 1, -1])]
    assert out == pytest.approx([0.0, 1.0, 1.0, 1.0, 0.0])
    assert pid.integral[0] == pytest.approx(0.0)


def test_output_is_clipped_to_the_limits():
    pid = PID(_constant(100.0, 0.0, 0.0), output_limits=(0.0, 255.0))
    assert pid(0.0, 90.0, np.array([0.0, 89.0, 95.0])).tolist() == [255.0, 100.0, 0.0]


def test_derivative_filter_is_a_first_order_lag():
    # τ = Δt gives α = 1/2: the filtered slope moves half-way to the raw one each sample.
    pid = PID(_constant(0.0, 0.0, 1.0), derivative_tau=0.1)
    pid(0.0, 0.0, np.array([0.0]))
    assert pid(0.1, 0.0, np.array([-1.0]))[0] == pytest.approx(5.0)  # raw 10
    assert pid(0.2, 0.0, np.array([-1.0]))[0] == pytest.approx(2.5)  # raw 0


def test_reset_forgets_the_past():
    pid = PID(_constant(1.0, 1.0, 1.0))
    pid(0.0, 1.0, np.array([0.0]))
    pid(1.0, 1.0, np.array([0.0]))
    pid.reset(3)
    assert pid(5.0, 1.0, np.zeros(3)).tolist() == [1.0, 1.0, 1.0]


def test_piecewise_schedule_is_constant_on_left_closed_subranges():
    s = GainSchedule("piecewise", ROWS, POINTS)
    assert s.boundaries.tolist() == [30.0, 60.0]
    for theta, row in [(0, 0), (29.999, 0), (30, 1), (59.999, 1), (60, 2), (90, 2), (-5, 0)]:
        assert s(theta).tolist() == ROWS[row].tolist(), theta


def test_fuzzy_schedule_is_continuous_and_linear_between_points():
    s = GainSchedule("fuzzy", ROWS, POINTS)
    assert s(15.0).tolist() == ROWS[0].tolist()
    assert s(30.0) == pytest.approx(0.5 * (ROWS[0] + ROWS[1]))
    assert s(0.0).tolist() == ROWS[0].tolist() and s(90.0).tolist() == ROWS[2].tolist()
    grid = np.linspace(0.0, 90.0, 9001)
    jumps = np.abs(np.diff(s(grid), axis=0)).max(axis=0)
    slope = np.abs(np.diff(ROWS, axis=0)).max(axis=0) / 30.0
    assert np.all(jumps <= slope * 0.01 + 1e-12)  # no step anywhere, incl. 30° and 60°
    piecewise = np.abs(np.diff(GainSchedule("piecewise", ROWS, POINTS)(grid), axis=0)).max(axis=0)
    assert np.all(piecewise == np.abs(np.diff(ROWS, axis=0)).max(axis=0))


def test_scheduled_pid_uses_the_gains_of_the_reference():
    # Eq. (2.4): K(θ_r) multiplies the whole error vector, the sum included.
    pid = PID(GainSchedule("piecewise", ROWS, POINTS), trials=1)
    pid(0.0, 20.0, np.array([10.0]))  # first sample: u = 1 * 10
    u = pid(1.0, 40.0, np.array([10.0]))  # e = 30, Σ = 30, Δe/Δt = 20 with row 1
    assert u[0] == pytest.approx(3 * 30 + 4 * 30 + 0.5 * 20)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"kind": "constant", "gains": ROWS}, "GainSchedule.gains"),
        ({"kind": "fuzzy", "gains": ROWS, "points": np.array([15.0, 45.0])}, "GainSchedule.points"),
        (
            {"kind": "fuzzy", "gains": ROWS, "points": np.array([15.0, 75.0, 45.0])},
            "GainSchedule.points",
        ),
        ({"kind": "fuzzy", "gains": np.ones((3, 2)), "points": POINTS}, "GainSchedule.gains"),
        ({"kind": "spline", "gains": ROWS, "points": POINTS}, "GainSchedule.kind"),
        ({"kind": "constant", "gains": np.array([[1.0, np.nan, 0.0]])}, "GainSchedule.gains"),
    ],
)
def test_bad_schedules_name_the_field(kwargs, field):
    with pytest.raises(ConfigError) as exc:
        GainSchedule(**kwargs)
    assert exc.value.field == field


def test_output_limits_must_be_ordered():
    with pytest.raises(ConfigError) as exc:
        PID(_constant(1, 1, 0), output_limits=(1.0, 0.0))
    assert exc.value.field == "PID.output_limits"


def test_derivative_filter_time_constant_must_not_be_negative():
    with pytest.raises(ConfigError) as exc:
        PID(_constant(1, 1, 0), derivative_tau=-1.0)
    assert exc.value.field == "PID.derivative_tau"


def test_sample_times_must_increase():
    pid = PID(_constant(1, 1, 0))
    pid(1.0, 0.0, np.zeros(1))
    with pytest.raises(ConfigError) as exc:
        pid(1.0, 0.0, np.zeros(1))
    assert exc.value.field == "PID.t"


def test_schedule_holds_read_only_copies():
    rows = ROWS.copy()
    s = GainSchedule("fuzzy", rows, POINTS)
    rows[0, 0] = 99.0  # the caller's array is copied
    assert s(15.0)[0] == 1.0
    with pytest.raises(ValueError):
        s.gains[0, 0] = 5.0
    with pytest.raises(ValueError):
        s.points[0] = 5.0
