"""Simulated PneuNet: exact valve/chamber update, duty-proportional pressure, sensor, batches."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from articula.control.pid import PID, GainSchedule
from articula.errors import ConfigError
from articula.experiments.ch2 import run_closed_loop
from articula.plants.pneunet import PneuNetBatch, PneuNetParams
from articula.tuning.response import Response, step_features, tuning_cost

P = PneuNetParams()


def _duty_response(duty: float, periods: int) -> PneuNetBatch:
    plant = PneuNetBatch(P, 1)
    for _ in range(periods):
        plant.advance(np.array([duty]))
    return plant


def test_valve_and_chamber_match_an_ode_solver_through_one_pwm_period():
    plant = PneuNetBatch(P, 1)
    plant.valve[:] = 0.3
    plant.pressure[:] = 12e3
    duty = 0.4
    plant.advance(np.array([duty]))

    def rhs(u):
        return lambda t, s: [(u - s[0]) / P.valve_tau,
                             (P.supply_pressure * s[0] - s[1]) / P.chamber_tau]  # fmt: skip

    on = solve_ivp(rhs(1.0), (0, duty * P.pwm_period), [0.3, 12e3], rtol=1e-11, atol=1e-9)
    sol = solve_ivp(rhs(0.0), (0, (1 - duty) * P.pwm_period), on.y[:, -1], rtol=1e-11,
                    atol=1e-9)  # fmt: skip
    assert plant.valve[0] == pytest.approx(sol.y[0, -1], rel=1e-6)
    assert plant.pressure[0] == pytest.approx(sol.y[1, -1], rel=1e-6)


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


def _pid(kp, ki, kd, trials=1):
    return PID(GainSchedule("constant", np.array([[kp, ki, kd]])), (0.0, 255.0), trials=trials)


def test_batch_trials_equal_single_trials_seed_by_seed():
    reference = 45.0 - 45.0 * np.cos(2 * np.pi * 0.2 * np.arange(150) / 30.0)
    seeds = [7, 8, 9, 10]
    batch = run_closed_loop(P, _pid(1.0, 2.0, 0.05, 4), reference, seeds)
    for i, seed in enumerate(seeds):
        single = run_closed_loop(P, _pid(1.0, 2.0, 0.05), reference, [seed])
        np.testing.assert_array_equal(batch.measured[i], single.measured[0])
        np.testing.assert_array_equal(batch.theta[i], single.theta[0])
        np.testing.assert_array_equal(batch.duty[i], single.duty[0])
    assert not np.array_equal(batch.measured[0], batch.measured[1])


def test_trials_vary_only_through_their_seed():
    reference = np.full(90, 45.0)
    a = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [3])
    b = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [3])
    nominal = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [3], vary=False)
    np.testing.assert_array_equal(a.theta, b.theta)
    assert not np.array_equal(a.theta, nominal.theta)


def _amplitude_ratio(frequency: float) -> float:
    """Closed-loop |θ/θ_r| at `frequency` [Hz] with the book's automatic gains at 45°."""
    steps = round(max(3 / frequency, 10.0) * 30)
    t = np.arange(steps) / 30.0
    reference = 45.0 - 30.0 * np.cos(2 * np.pi * frequency * t)
    trace = run_closed_loop(P, _pid(1.48, 3.77, 0.0), reference, [0], vary=False)
    keep = t >= t[-1] / 3
    basis = np.stack([np.ones(keep.sum()), np.sin(2 * np.pi * frequency * t[keep]),
                      np.cos(2 * np.pi * frequency * t[keep])], axis=1)  # fmt: skip
    coef = np.linalg.lstsq(basis, trace.theta[0, keep], rcond=None)[0]
    return float(np.hypot(coef[1], coef[2]) / 30.0)


def test_calibration_tracks_half_a_hertz_but_not_five():
    # Sect. 2.4.2.2: tracks sinusoids up to about 0.5 Hz; cannot follow 5 Hz.
    assert _amplitude_ratio(0.05) > 0.9
    assert _amplitude_ratio(0.5) > 0.5
    assert _amplitude_ratio(5.0) < 0.1


def test_calibration_a_derivative_term_makes_it_oscillate():
    # Sect. 2.4.2.1: K_d ≠ 0 gives oscillations; compare swings and M (2.5) at 45°.
    reference = np.full(240, 45.0)
    results = {}
    for kd in (0.0, 0.3):
        tr = run_closed_loop(P, _pid(1.0, 2.0, kd), reference, [1], vary=False)
        r = Response(tr.t, tr.reference, tr.measured[0])
        results[kd] = (step_features(r, 2.0), float(tuning_cost(r.t, r.reference, r.measured)))
        results[kd] += (float(np.mean(np.abs(np.diff(tr.duty[0])))),)
    assert results[0.3][1] > 1.5 * results[0.0][1]  # M
    assert results[0.3][2] > 5 * results[0.0][2]  # the valve chatters


@pytest.mark.parametrize(
    ("update", "word"),
    [
        ({"valve_tau": 0.25}, "valve_tau"),
        ({"supply_pressure": 10e3}, "supply_pressure"),
        ({"damping_ratio": 1.5}, "damping_ratio"),
        ({"adc_bits": 30}, "adc_bits"),
        ({"trial_spread": -0.1}, "trial_spread"),
    ],
)
def test_bad_parameters_name_the_field(update, word):
    with pytest.raises(ConfigError) as exc:
        PneuNetParams(**update)
    assert word in str(exc.value)
