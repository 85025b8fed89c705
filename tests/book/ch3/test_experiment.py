"""Chapter 3's experiment: metrics, the valve program it runs, bad input, the registered run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.control.chamber_allocation import side_pressures
from articula.control.damping import DampingPolicy
from articula.errors import ConfigError
from articula.experiments.six_chamber import (
    DeactuationConfig,
    oscillation_metrics,
    run_deactuation,
    run_metrics,
    simulate_deactuation,
)
from articula.loops.six_chamber import valve_program
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import SixChamberParams
from articula.plants.six_chamber_sim import FILL, HOLD, REGULATE, VENT, ValveSchedule, fill_time
from articula.runs.registry import parse_config

P = SixChamberParams()
IDEAL = OrientationSensorParams(ideal=True)


def metrics(**damping) -> dict[str, float]:
    config = DeactuationConfig(sensor=IDEAL, damping=DampingPolicy(**damping))
    return run_metrics(simulate_deactuation(config), config.band_deg)


def program(config: DeactuationConfig) -> ValveSchedule:
    return valve_program(config.actuator, config.side_deg, config.gauge, config.hold,
                         config.damping)  # fmt: skip


# ----- metrics -----------------------------------------------------------------------------------


def test_oscillation_metrics_of_a_damped_cosine():
    t = np.arange(0, 5, 1e-4)
    sigma, w = 2.0, 2 * math.pi
    angle = np.where(t < 1, 1.0, np.exp(-sigma * (t - 1)) * np.cos(w * (t - 1)))
    m = oscillation_metrics(t, angle, 1.0, band=0.1)
    assert m["start"] == 1.0
    # First trough where tan(wt) = −σ/w; the envelope e^{-σt} reaches the band at ln(10)/σ,
    # and the last exit from the band comes at most half a period before that.
    t1 = (math.pi - math.atan(sigma / w)) / w
    trough = -math.exp(-sigma * t1) * math.cos(w * t1)
    assert m["peak"] == pytest.approx(trough, rel=1e-6)
    assert m["overshoot"] == pytest.approx(trough, rel=1e-6)
    assert math.log(10) / sigma - 0.5 < m["settling"] <= math.log(10) / sigma


def test_metrics_of_a_response_that_never_crosses_or_settles():
    t = np.linspace(0, 2, 2001)
    m = oscillation_metrics(t, np.exp(-t), 0.0, band=0.01)
    assert m["peak"] == 0.0 and m["overshoot"] == 0.0 and math.isnan(m["settling"])


# ----- the damping policy and the valve program --------------------------------------------------


def test_no_damping_no_events():
    assert DampingPolicy().events(P, np.eye(6)[0] * P.supply, 1.0) == []


def test_pulse_goes_to_the_opposite_chamber_at_delta_times_the_pressure():
    policy = DampingPolicy(delta=0.5, start=0.02, length=0.05)
    events = policy.events(P, np.eye(6)[1] * 80e3, 1.0)
    t_open = fill_time(P, 40e3)
    assert 0 < t_open < 0.05
    assert events == [(1.02, 4, FILL), (1.02 + t_open, 4, HOLD), (1.07, 4, VENT)]


def test_a_pulse_shorter_than_its_fill_vents_once_filled():
    brief = DampingPolicy(delta=0.5, length=0.001)
    assert brief.events(P, np.eye(6)[1] * 80e3, 1.0)[-1] == (1.0 + fill_time(P, 40e3), 4, VENT)


def test_between_chambers_the_pulse_is_shared_by_two_opposite_chambers():
    config = DeactuationConfig(side_deg=30.0, damping=DampingPolicy(delta=0.4))
    s = program(config)
    pulsed = set(s.chambers[(s.times >= config.hold) & (s.modes == FILL)].tolist())
    assert pulsed == {3, 4}


@pytest.mark.parametrize(("side", "gauge"), [(30.0, None), (0.0, 50e3), (75.0, 80e3)])
def test_a_side_is_held_at_its_commanded_pressure(side, gauge):
    """Regulated chambers reach the vent command at the commanded pressure (Eq. 3.4's P)."""
    config = DeactuationConfig(side_deg=side, pressure=gauge, sensor=IDEAL, after=0.05)
    run = simulate_deactuation(config)
    commanded = side_pressures(side, config.gauge)
    at_vent = run.sim.gauge[np.searchsorted(run.sim.t, config.hold) - 1]
    np.testing.assert_allclose(at_vent, commanded, atol=0.01 * config.gauge)
    s = program(config)
    first = {int(c): int(m) for c, m in zip(s.chambers[::-1], s.modes[::-1], strict=True)}
    for i in np.nonzero(commanded)[0]:
        assert first[i] == (FILL if commanded[i] >= P.supply else REGULATE)


def test_between_chambers_the_bend_equals_one_chamber_at_full_supply():
    """Force vectors add: two chambers sharing a side bend the body as far as one."""
    angle = [run_metrics(simulate_deactuation(DeactuationConfig(side_deg=s, sensor=IDEAL,
                                                                after=0.05)),
                         1.0)["deactuation_angle_deg"] for s in (0.0, 30.0)]  # fmt: skip
    assert angle[1] == pytest.approx(angle[0], rel=0.01)


def test_a_short_hold_vents_while_filling():
    s = program(DeactuationConfig(side_deg=30.0, hold=0.001, after=0.2))
    assert HOLD not in s.modes.tolist()
    assert s.modes[-1] == VENT


def test_simultaneous_held_pulse_swings_further_past_rest():
    """The opposite chamber pushes the way the body returns (Sect. 3.2.4 against Fig. 3.5)."""
    assert metrics(delta=0.5, length=0.1)["peak_true_deg"] > metrics()["peak_true_deg"] + 5


def test_a_delayed_pulse_damps_the_swings_after_the_first():
    free = metrics()
    timed = metrics(delta=0.3, start=0.15, length=0.045)
    assert timed["settling_true_s"] < 0.3 * free["settling_true_s"]
    assert timed["peak_true_deg"] == pytest.approx(free["peak_true_deg"], abs=0.1)


# ----- bad input ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("data", "field"),
    [
        ({"damping": {"delta": 1.2}}, "damping.delta"),
        ({"damping": {"start": -0.1}}, "damping.start"),
        ({"actuator": {"supply": 0.0}}, "actuator.supply"),
        ({"sensor": {"rate": 0.0}}, "sensor.rate"),
        ({"side": 30.0}, "side"),
        ({"pressure": 2e5}, "pressure"),
        ({"dt": 3e-4}, "dt"),
        ({"actuator": {"chamber_length": 0.2}}, "actuator.chamber_length"),
    ],
)
def test_bad_config_names_the_field(data, field):
    with pytest.raises(ConfigError) as exc:
        parse_config({"experiment": "softarm.damping", **data})
    assert exc.value.field == field


@pytest.mark.parametrize(
    ("data", "words"),
    [
        ({"pressure": 2e5}, "above the supply"),
        ({"dt": 3e-4}, "must divide"),
        ({"dt": 1e-6, "after": 10.0}, "5e6 steps"),
    ],
)
def test_cross_field_checks_say_what_is_wrong(data, words):
    with pytest.raises(ConfigError) as exc:
        DeactuationConfig(**data)
    assert words in exc.value.problem


# ----- the registered run ------------------------------------------------------------------------


def test_registered_run_returns_trace_columns_of_one_length():
    result = run_deactuation(DeactuationConfig(hold=0.5, after=0.3))
    lengths = {v.size for v in result.trace.values()}
    assert len(lengths) == 1
    assert {"t", "bend", "bend_sensor", "p0", "valve5"} <= set(result.trace)
    assert set(result.metrics) >= {"peak_deg", "overshoot_pct", "settling_s"}


def test_a_sensor_too_slow_for_the_time_after_the_vent_command_is_refused():
    with pytest.raises(ConfigError) as err:
        DeactuationConfig(hold=0.05, after=0.05, sensor={"rate": 1.0})
    assert err.value.field == "DeactuationConfig.after" and "sensor.rate" in err.value.problem
