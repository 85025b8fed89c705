"""plants/six_chamber_sim.py: the six-chamber actuator integrated over time: energy balance, free
response against the linear model, statics reached, valves (fill, hold, regulate) and refusals."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.plants.six_chamber import (
    CHAMBERS,
    SixChamberParams,
    chamber_directions,
    gas_stiffness,
    natural_frequency,
    static_bend,
    volume_gradients,
)
from articula.plants.six_chamber_sim import (
    FILL,
    HOLD,
    REGULATE,
    ValveSchedule,
    fill_time,
    integrate,
)

P = SixChamberParams()
SEALED = np.full(CHAMBERS, HOLD)


def total_energy(p: SixChamberParams, sim) -> np.ndarray:
    """Body energy plus, per sealed chamber, its air's internal energy and p_atm·V (Joules)."""
    mech = 0.5 * p.inertia * np.sum(sim.rate**2, 1) + 0.5 * p.stiffness * np.sum(sim.beta**2, 1)
    volume = p.chamber_volume + sim.beta @ volume_gradients(p).T
    absolute = sim.gauge + p.atmosphere
    gas = absolute * volume / (p.polytropic - 1) + p.atmosphere * volume
    return mech + gas.sum(1)


# ----- physics checks (issue 6) -----------------------------------------------------------------


def test_energy_decays_with_no_input():
    beta0 = (math.radians(10.0), math.radians(-4.0))
    sim = integrate(P, ValveSchedule.build([]), 2.0, beta0=beta0, modes0=SEALED)
    energy = total_energy(P, sim)
    assert np.all(np.diff(energy) <= 1e-12 * energy[0])
    excess = energy - energy[-1]
    assert excess[-1] < 1e-3 * excess[0]
    # Vented chambers (the idle state) lose it too; only the body's energy is left to count.
    vented = integrate(P, ValveSchedule.build([]), 2.0, beta0=beta0)
    body = 0.5 * P.inertia * np.sum(vented.rate**2, 1) + 0.5 * P.stiffness * np.sum(
        vented.beta**2, 1
    )
    assert body[-1] < 1e-4 * body[0]


def test_energy_is_conserved_without_friction():
    """The oracle behind the decay test: with b = 0 the sealed air stores and returns energy."""
    p = P.model_copy(update={"damping": 0.0})
    sim = integrate(p, ValveSchedule.build([]), 0.5, beta0=(0.2, 0.1), modes0=SEALED)
    energy = total_energy(p, sim)
    swing = 0.5 * p.stiffness * 0.05
    assert np.ptp(energy) < 1e-6 * swing


@pytest.mark.parametrize("pair", [(0, 3), (1, 4), (2, 5)])
def test_opposite_equal_pressures_give_no_bend(pair):
    events = [(0.0, c, FILL) for c in pair] + [(0.4, c, HOLD) for c in pair]
    sim = integrate(P, ValveSchedule.build(events), 0.8)
    assert sim.gauge[:, pair[0]].max() > 0.9 * P.supply
    np.testing.assert_allclose(sim.gauge[:, pair[0]], sim.gauge[:, pair[1]], atol=1e-9)
    assert np.abs(sim.beta).max() < 1e-12


def test_natural_frequency_and_damping_ratio_match_the_free_response():
    """Small free swing with every valve holding: I θ'' + b θ' + (V E k² + gas) θ = 0.

    The air is sealed at atmospheric pressure with the body bent by θ0, so the gas spring
    holds it toward θ0: the rest angle is θ0·K_gas/(K + K_gas).
    """
    wn, zeta = natural_frequency(P, sealed=True)
    theta0 = math.radians(0.5)
    rest = theta0 * gas_stiffness(P, P.atmosphere) / (P.stiffness + gas_stiffness(P, P.atmosphere))
    sim = integrate(P, ValveSchedule.build([]), 1.0, beta0=(theta0, 0.0), modes0=SEALED)
    wd = wn * math.sqrt(1 - zeta**2)
    t = sim.t
    closed = rest + (theta0 - rest) * np.exp(-zeta * wn * t) * (
        np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t)
    )
    np.testing.assert_allclose(sim.beta[:, 0], closed, atol=2e-3 * theta0)
    # Without the gas spring the prediction is off by far more than that tolerance.
    wn_body, _ = natural_frequency(P)
    assert abs(wn_body - wn) / wn > 0.1


def test_linear_frequency_of_vented_body_is_close_but_damped_more():
    """Vented chambers pass air through their orifices: a softer spring and extra damping."""
    wn, zeta = natural_frequency(P)
    sim = integrate(P, ValveSchedule.build([]), 1.0, beta0=(math.radians(2.0), 0.0))
    x = sim.beta[:, 0]
    up = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    period = np.mean(np.diff(sim.t[up]))
    assert 2 * math.pi / period == pytest.approx(wn * math.sqrt(1 - zeta**2), rel=0.1)
    peaks = [x[a:b].max() for a, b in itertools.pairwise(up)]
    measured_zeta = np.log(peaks[0] / peaks[1]) / (2 * math.pi)
    assert measured_zeta > zeta


# ----- statics, valves ----------------------------------------------------------------------------


def test_steady_bend_matches_the_static_model():
    # Connected to the pump the chamber sits at the supply pressure: the static model holds.
    sim = integrate(P, ValveSchedule.build([(0.0, 2, FILL)]), 4.0)
    expected = static_bend(P, np.eye(CHAMBERS)[2] * P.supply)
    np.testing.assert_allclose(sim.beta[-1], expected, rtol=1e-4)
    assert expected @ chamber_directions()[2] < 0  # bends away from the chamber


def test_pressure_stiffening_scales_the_steady_bend():
    # V E k²·(1 + s p/supply) θ = A_c r_p p for one chamber held at the supply pressure.
    p = P.model_copy(update={"stiffening": 0.8})
    sim = integrate(p, ValveSchedule.build([(0.0, 0, FILL)]), 4.0)
    expected = static_bend(P, np.eye(CHAMBERS)[0] * P.supply) / 1.8
    np.testing.assert_allclose(sim.beta[-1], expected, rtol=1e-4, atol=1e-12)


def test_fill_time_brings_a_still_chamber_to_its_target():
    target = 0.4 * P.supply
    t_open = fill_time(P, target)
    events = [(0.0, 0, FILL), (0.0, 3, FILL), (t_open, 0, HOLD), (t_open, 3, HOLD)]
    sim = integrate(P, ValveSchedule.build(events), 0.1, dt=1e-5, record_every=1)
    assert sim.gauge[-1, 0] == pytest.approx(target, rel=2e-3)
    assert fill_time(P, 0.0) == 0.0 and math.isinf(fill_time(P, P.supply))
    assert fill_time(P, 0.2 * P.supply) < t_open < fill_time(P, 0.8 * P.supply)


def test_regulated_chamber_holds_its_target_while_the_body_swings():
    """REGULATE refills and vents against the bend; HOLD after a timed fill drifts."""
    target = 0.5 * P.supply
    regulated = integrate(P, ValveSchedule.build([(0.0, 0, REGULATE, target)]), 3.0)
    late = regulated.t >= 0.3
    np.testing.assert_allclose(regulated.gauge[late, 0], target, rtol=0.01)
    np.testing.assert_allclose(regulated.beta[-1], static_bend(P, np.eye(CHAMBERS)[0] * target),
                               rtol=0.01, atol=1e-12)  # fmt: skip
    held = integrate(P, ValveSchedule.build([(0.0, 0, FILL), (fill_time(P, target), 0, HOLD)]), 1.0)
    assert held.gauge[-1, 0] < 0.9 * target  # the bend expands the sealed chamber


@pytest.mark.parametrize(
    ("events", "field"),
    [
        ([(0.0, 6, FILL)], "events[0].chamber"),
        ([(0.0, 1, FILL), (0.1, 2, 7)], "events[1].mode"),
        ([(0.0, 1, REGULATE)], "events[0].target"),
    ],
)
def test_bad_schedule_names_the_event(events, field):
    with pytest.raises(ConfigError) as exc:
        ValveSchedule.build(events)
    assert exc.value.field == field


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"dt": 0.01}, "dt"),
        ({"duration": 0.0}, "duration"),
        ({"record_every": 0}, "record_every"),
        ({"modes0": np.full(CHAMBERS, 3)}, "modes0"),
        ({"modes0": np.zeros(5, int)}, "modes0"),
    ],
)
def test_bad_simulation_arguments_name_the_argument(kwargs, field):
    args = {"duration": 1.0, **kwargs}
    with pytest.raises(ConfigError) as exc:
        integrate(P, ValveSchedule.build([]), **args)
    assert exc.value.field == field
