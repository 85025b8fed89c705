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


def test_a_trial_is_the_same_actuator_whatever_the_run_length():
    # The actuator variation has its own stream, so the first samples of a short run equal
    # those of a long run of the same seed (the old order, noise then variation, failed this).
    reference = 45.0 - 45.0 * np.cos(2 * np.pi * 0.5 * np.arange(300) / 30.0)
    short = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference[:60], [4])
    long = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [4])
    np.testing.assert_array_equal(short.theta[0], long.theta[0, :60])
    np.testing.assert_array_equal(short.measured[0], long.measured[0, :60])
    nominal = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference[:60], [4], vary=False)
    np.testing.assert_array_equal(short.measured[0, :1], nominal.measured[0, :1])  # same noise
    assert not np.array_equal(short.theta[0], nominal.theta[0])


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


@pytest.mark.parametrize("seed", [1, 2])
def test_calibration_a_large_derivative_term_makes_it_oscillate(seed):
    # Sect. 2.4.2.1: K_d ≠ 0 gives oscillations. At a 45° step, K_d = 0.3 makes the true angle
    # swing beyond the 2° band without dying out; K_d = 0 gives no swing at all.
    reference = np.full(240, 45.0)
    results = {}
    for kd in (0.0, 0.3):
        tr = run_closed_loop(P, _pid(1.0, 2.0, kd), reference, [seed], vary=False)
        true = step_features(Response(tr.t, tr.reference, tr.theta[0]), 2.0)
        cost = float(tuning_cost(tr.t, tr.reference, tr.measured[0]))
        results[kd] = (true, cost)
    swinging, calm = results[0.3][0], results[0.0][0]
    assert swinging.sustained() and swinging.peak_sizes.size >= 10
    assert swinging.peak_sizes[-4:].min() > 5.0  # still > 5° at the end of the 8 s
    assert calm.peak_sizes.size == 0
    assert results[0.3][1] > 1.5 * results[0.0][1]  # M (2.5)


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
