"""plants/pneunet.py: the simulated PneuNet's exact valve/chamber update against an ODE solver,
duty-proportional pressure, bending, sensor, batches of varied trials and parameter checks."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from articula.errors import ConfigError
from articula.plants.pneunet import PneuNetBatch, PneuNetParams

P = PneuNetParams()


def _duty_response(duty: float, periods: int) -> PneuNetBatch:
    plant = PneuNetBatch(P, 1)
    for _ in range(periods):
        plant.advance(np.array([duty]))
    return plant


@pytest.mark.parametrize(
    ("valve_tau", "chamber_tau"),
    [(0.2 / 3, 0.25), (0.25, 0.25), (0.2, 0.25), (0.25, 0.25 * (1 + 1e-9)), (0.5, 0.1)],
)
def test_valve_and_chamber_match_an_ode_solver_through_one_pwm_period(valve_tau, chamber_tau):
    # Includes the repeated pole τ_v = τ_p, a pair 1e-9 apart and τ_v > τ_p.
    params = P.model_copy(update={"valve_tau": valve_tau, "chamber_tau": chamber_tau})
    plant = PneuNetBatch(params, 1)
    plant.valve[:] = 0.3
    plant.pressure[:] = 12e3
    duty = 0.4
    plant.advance(np.array([duty]))

    def rhs(u):
        return lambda t, s: [(u - s[0]) / valve_tau,
                             (P.supply_pressure * s[0] - s[1]) / chamber_tau]  # fmt: skip

    on = solve_ivp(rhs(1.0), (0, duty * P.pwm_period), [0.3, 12e3], rtol=1e-11, atol=1e-9)
    sol = solve_ivp(rhs(0.0), (0, (1 - duty) * P.pwm_period), on.y[:, -1], rtol=1e-11,
                    atol=1e-9)  # fmt: skip
    assert plant.valve[0] == pytest.approx(sol.y[0, -1], rel=1e-6)
    assert plant.pressure[0] == pytest.approx(sol.y[1, -1], rel=1e-6)


def test_trial_factors_can_put_the_chamber_pole_on_the_valve_pole():
    # Trial 1's chamber τ scaled onto τ_v: the repeated-pole case inside a batch stays finite
    # and equals the same actuator built with chamber_tau = valve_tau.
    factors = np.array([[1.0, 1.0, 1.0], [1.0, P.valve_tau / P.chamber_tau, 1.0]])
    batch = PneuNetBatch(P, 2, factors)
    alone = PneuNetBatch(P.model_copy(update={"chamber_tau": P.valve_tau}), 1)
    for _ in range(20):
        batch.advance(np.array([0.7, 0.7]))
        alone.advance(np.array([0.7]))
    assert np.all(np.isfinite(batch.pressure))
    assert batch.pressure[1] == pytest.approx(alone.pressure[0], rel=1e-12)
    assert batch.theta[1] == pytest.approx(alone.theta[0], rel=1e-12)


@pytest.mark.parametrize(
    "factors", [np.ones((3, 3)), np.ones((2, 2)), np.ones(6), -np.ones((2, 3))]
)
def test_batch_rejects_factors_of_the_wrong_shape(factors):
    with pytest.raises(ConfigError) as exc:
        PneuNetBatch(P, 2, factors)
    assert exc.value.field == "factors"


def test_batch_needs_at_least_one_trial():
    with pytest.raises(ConfigError) as exc:
        PneuNetBatch(P, 0)
    assert exc.value.field == "trials"


@pytest.mark.parametrize("duty", [0.2, 0.5, 0.8])
def test_mean_pressure_is_proportional_to_duty(duty):
    # Sect. 2.4.1.2: the pressure is proportional to the PWM duty. In periodic steady state
    # the mean of a first-order lag of the PWM wave equals the duty, so mean p = duty·P_s.
    plant = _duty_response(duty, 300)
    samples = []
    for _ in range(30):
        plant.advance(np.array([duty]))
        samples.append(plant.pressure[0])
    assert np.mean(samples) == pytest.approx(duty * P.supply_pressure, rel=0.02)


def test_bending_settles_at_the_static_map_and_covers_0_to_90_degrees():
    plant = _duty_response(0.6, 600)
    mean_p = 0.6 * P.supply_pressure
    assert plant.theta[0] == pytest.approx(P.equilibrium_angle(mean_p), rel=0.02)
    assert math.degrees(P.equilibrium_angle(P.supply_pressure)) > 90.0
    p = np.linspace(0, P.supply_pressure, 50)
    assert np.all(np.diff(P.equilibrium_angle(p)) > 0)
    assert np.all(np.diff(P.equilibrium_angle(p), 2) < 0)  # saturating


def test_bending_is_lightly_damped():
    # A step in pressure target overshoots: ζ = 0.15 gives exp(-πζ/√(1-ζ²)) ≈ 62 % overshoot
    # of the bending alone; the valve and chamber lags smooth it, but the angle still overshoots.
    plant = _duty_response(1.0, 1)
    peak = 0.0
    for _ in range(200):
        plant.advance(np.array([1.0]))
        peak = max(peak, plant.theta[0])
    assert peak > plant.theta[0]


def test_sensor_quantises_to_the_10_bit_adc_without_noise():
    params = P.model_copy(update={"sensor_noise": 0.0})
    plant = PneuNetBatch(params, 3)
    plant.theta[:] = np.radians([0.0, 33.3, 89.0])
    reading = plant.read(np.zeros(3))
    lsb_angle = params.adc_vref / 2**params.adc_bits / params.sensor_gain
    assert np.all(np.abs(reading - plant.theta) <= lsb_angle / 2 + 1e-12)
    assert math.degrees(lsb_angle) == pytest.approx(0.176, abs=1e-3)


def test_hysteresis_plays_the_pressure():
    params = P.model_copy(update={"hysteresis": 10e3})
    rising = PneuNetBatch(params, 1)
    plain = PneuNetBatch(P, 1)
    for _ in range(200):
        rising.advance(np.array([0.5]))
        plain.advance(np.array([0.5]))
    assert rising.theta[0] < plain.theta[0]  # the played pressure lags by half the width


@pytest.mark.parametrize(
    ("update", "word"),
    [
        ({"valve_tau": -0.25}, "valve_tau"),
        ({"supply_pressure": 10e3}, "supply_pressure"),
        ({"theta_max": 1.0}, "supply_pressure"),
        ({"damping_ratio": 1.5}, "damping_ratio"),
        ({"adc_bits": 30}, "adc_bits"),
        ({"trial_spread": -0.1}, "trial_spread"),
    ],
)
def test_bad_parameters_name_the_field(update, word):
    with pytest.raises(ConfigError) as exc:
        PneuNetParams(**update)
    assert exc.value.loc == (word,), exc.value


def test_close_time_constants_are_accepted():
    # The exact update has a repeated-pole form, so τ_v need not stay away from τ_p.
    assert PneuNetParams(valve_tau=0.25, chamber_tau=0.25).valve_tau == 0.25
