"""Closed-loop current control of Sect. 4.4 (compiled loop, streaming metrics, linear model)."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from oracles import rise_time, sinusoid_fit
from scipy.signal import cont2discrete, dlsim

from articula.control.current_loop_linear import bandwidth, closed_loop, is_stable, pi_discrete
from articula.control.moving_average import moving_average
from articula.errors import ConfigError
from articula.experiments.ch4 import (
    CurrentControlConfig,
    loop_settings,
    run_current_control,
    simulate_batch,
    time_axis,
)
from articula.plants.motor_rig import discretize, rig_matrices
from articula.validation import parse_model

TABLE_4_2_DICT = {"R": 8.35, "K": 0.4485, "b": 0.002, "J": 0.1}
IDEAL = {"sensor": {"ideal": True}, "encoder": {"ideal": True}, "pwm": {"bits": 0}}


def config(**fields) -> CurrentControlConfig:
    return parse_model(CurrentControlConfig, fields)


def linear_loop(cfg: CurrentControlConfig) -> control.StateSpace:
    Ad, Bd = discretize(*rig_matrices(cfg.params, cfg.rig == "dual"), cfg.dt)
    return closed_loop(Ad, Bd, loop_settings(cfg))


def noisy_config(**extra) -> CurrentControlConfig:
    """The book's unfiltered-or-filtered rig with every non-ideality on, kept short."""
    return config(duration=0.6, settle=0.3, **extra)


# ----------------------------------------------------------------------- reproducibility


@pytest.mark.parametrize("trials", [2, 5, 16])
def test_trial_zero_of_a_batch_is_the_single_run_bitwise(trials: int):
    cfg = noisy_config(seed=7, controller={"filter_order": 4})
    single = run_current_control(cfg)
    channels, metrics = simulate_batch(cfg, trials)
    assert channels is not None
    for name, trace in channels.items():
        assert trace.shape == (trials, cfg.steps)
        np.testing.assert_array_equal(trace[0], single.trace[name], err_msg=name)
    for name, value in metrics.items():
        np.testing.assert_array_equal(value[0], single.metrics[name], err_msg=name)
    # The other trials see other noise.
    assert not np.array_equal(channels["i_meas"][1], channels["i_meas"][0])


def test_a_trial_does_not_depend_on_the_batch_size():
    cfg = noisy_config(seed=8)
    small, m_small = simulate_batch(cfg, 2)
    large, m_large = simulate_batch(cfg, 9)
    for name in small:
        np.testing.assert_array_equal(small[name], large[name][:2], err_msg=name)
    for name in m_small:
        np.testing.assert_array_equal(m_small[name], m_large[name][:2], err_msg=name)


def test_same_seed_same_numbers_other_seed_other_numbers():
    a = run_current_control(noisy_config(seed=3))
    b = run_current_control(noisy_config(seed=3))
    c = run_current_control(noisy_config(seed=4))
    for name in a.trace:
        np.testing.assert_array_equal(a.trace[name], b.trace[name], err_msg=name)
    assert a.metrics.keys() == b.metrics.keys()
    for name in a.metrics:
        np.testing.assert_array_equal(a.metrics[name], b.metrics[name], err_msg=name)
    assert not np.array_equal(a.trace["i_meas"], c.trace["i_meas"])
    assert not np.array_equal(a.trace["i"], c.trace["i"])
    assert a.metrics["noise_rms"] != c.metrics["noise_rms"]


def test_unrecorded_batch_has_the_same_metrics():
    cfg = noisy_config(seed=1, controller={"filter_order": 8})
    channels, recorded = simulate_batch(cfg, 3, record=True)
    none, streamed = simulate_batch(cfg, 3, record=False)
    assert channels is not None
    assert none is None
    for name in recorded:
        np.testing.assert_array_equal(recorded[name], streamed[name], err_msg=name)


# ---------------------------------------------------------- loop internals against oracles


def test_fed_back_current_is_the_moving_average_of_the_measurement():
    k = 16
    cfg = noisy_config(seed=2, controller={"filter_order": k})
    ch, _ = simulate_batch(cfg, 3)
    np.testing.assert_allclose(ch["i_fb"], moving_average(ch["i_meas"], k), atol=1e-12)
    # The sensor really is noisy and quantised here, so the check is not vacuous.
    assert np.std(ch["i_meas"][:, -200:] - ch["i"][:, -200:]) > 5e-3


def test_applied_voltage_is_the_pwm_level_of_the_duty_register():
    cfg = noisy_config(seed=5)
    ch, _ = simulate_batch(cfg, 2)
    duty = ch["duty1"]
    np.testing.assert_array_equal(duty, np.round(duty))
    assert np.abs(duty).max() <= 255
    np.testing.assert_allclose(ch["v1"], duty * 12.0 / 256, rtol=0, atol=1e-12)
    # The start of a 1 A step from rest drives the register to full scale.
    assert duty[0, 0] == 255
    # The secondary's voltage is quantised the same way.
    np.testing.assert_allclose(ch["v2"] * 256 / 12.0, np.round(ch["v2"] * 256 / 12.0), atol=1e-9)


@pytest.mark.parametrize("bits", [0, 8])
def test_controller_laws_eq_4_12_and_4_14_reproduced_from_the_trace(bits: int):
    cfg = noisy_config(seed=9, controller={"filter_order": 4}, pwm={"bits": bits})
    ch, _ = simulate_batch(cfg, 2)
    p, dt, v_max = cfg.params, cfg.dt, 12.0
    lsb = v_max / 2**bits

    def driver(v: np.ndarray) -> np.ndarray:
        if bits == 0:
            return np.clip(v, -v_max, v_max)
        counts = np.minimum(np.floor(np.minimum(np.abs(v), v_max) / lsb), 2**bits - 1)
        return np.sign(v) * counts * lsb

    # Eq. (4.14) with e = i_ref − i_fb about the Eq. (4.13) bias; the sum includes e[n].
    e = ch["i_ref"] - ch["i_fb"]
    v1 = driver(p.R * 1.0 + p.K * 5.0 + 10.0 * e + 100.0 * dt * np.cumsum(e, axis=1))
    # Eq. (4.12) on the encoder's speed, negated for the reversed secondary.
    e_w = 5.0 - ch["omega_meas"]
    v2 = driver(-(5.0 * e_w + 10.0 * dt * np.cumsum(e_w, axis=1)))
    if bits == 0:
        np.testing.assert_allclose(ch["v1"], v1, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ch["v2"], v2, rtol=1e-9, atol=1e-9)
    else:
        # Summation order may move a command across a register boundary: one LSB at most,
        # and almost never.
        assert np.abs(ch["v1"] - v1).max() <= lsb + 1e-12
        assert np.mean(ch["v1"] != v1) < 0.01
        assert np.abs(ch["v2"] - v2).max() <= lsb + 1e-12
        assert np.mean(ch["v2"] != v2) < 0.01


@pytest.mark.parametrize("rig", ["single", "dual"])
def test_recorded_states_follow_the_zoh_rig_driven_by_the_recorded_voltages(rig: str):
    # Replay the applied voltages through scipy's own ZOH model of the rig from rest.
    cfg = noisy_config(seed=4, rig=rig, reference={"current": 0.05 if rig == "single" else 1.0})
    ch, _ = simulate_batch(cfg, 2)
    A, B = rig_matrices(cfg.params, rig == "dual")
    n = A.shape[0]
    C = np.eye(n)[[1, 2]]  # ω, i₁
    sys = cont2discrete((A, B, C, np.zeros((2, 2))), cfg.dt, method="zoh")
    for trial in range(2):
        u = np.column_stack([ch["v1"][trial], ch["v2"][trial]])
        _, y, _ = dlsim(sys, u, x0=np.zeros(n))
        np.testing.assert_allclose(ch["omega"][trial], y[:, 0], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ch["i"][trial], y[:, 1], rtol=1e-9, atol=1e-9)
    if rig == "single":
        np.testing.assert_array_equal(ch["v2"], 0.0)


def test_streaming_metrics_equal_metrics_computed_from_the_trace():
    k = 4
    cfg = config(seed=11, duration=1.0, settle=0.4, controller={"filter_order": k})
    ch, m = simulate_batch(cfg, 3)
    t = time_axis(cfg)
    steady = t >= cfg.settle
    i, i_ref = ch["i"][:, steady], ch["i_ref"][:, steady]
    np.testing.assert_allclose(m["steady_state_error"], (i - i_ref).mean(axis=1), atol=1e-12)
    np.testing.assert_allclose(
        m["current_rms_error"], np.sqrt(((i - i_ref) ** 2).mean(axis=1)), rtol=1e-9
    )
    noise = ch["i_fb"][:, steady] - moving_average(ch["i"], k)[:, steady]
    np.testing.assert_allclose(m["noise_rms"], np.sqrt((noise**2).mean(axis=1)), rtol=1e-9)
    np.testing.assert_allclose(m["speed_mean"], ch["omega"][:, steady].mean(axis=1), rtol=1e-12)
    saturated = np.abs(ch["duty1"]) >= 255
    np.testing.assert_allclose(m["saturation_fraction"], saturated.mean(axis=1), rtol=1e-12)
    np.testing.assert_allclose(m["rise_time"], rise_time(t, ch["i"], 0.0, 1.0), atol=1e-12)
    np.testing.assert_allclose(
        m["rise_time_feedback"], rise_time(t, ch["i_fb"], 0.0, 1.0), atol=1e-12
    )
    assert np.all(np.isnan(m["amplitude_ratio"]))


def test_streaming_sinusoid_fit_equals_least_squares_on_the_trace():
    w = 25.0
    cfg = config(seed=12, duration=1.5, settle=0.7, reference={"amplitude": 0.1, "frequency": w})
    ch, m = simulate_batch(cfg, 2)
    t = time_axis(cfg)
    steady = t >= cfg.settle
    amplitude, phase = sinusoid_fit(t[steady], ch["i"][:, steady], w)
    np.testing.assert_allclose(m["amplitude_ratio"], amplitude / 0.1, rtol=1e-8)
    np.testing.assert_allclose(m["phase_lag"], -phase, atol=1e-8)
    assert np.all(np.isnan(m["rise_time"]))


def test_encoder_speed_estimate_tracks_the_shaft_in_steady_state():
    cfg = config(seed=0, duration=6.0, settle=4.0, sensor={"ideal": True})
    ch, _ = simulate_batch(cfg, 1)
    late = slice(4000, None)
    # One count over the 50-sample window is 2π/375/0.05 = 0.335 rad/s.
    assert np.abs(ch["omega_meas"][0, late] - ch["omega"][0, late]).max() < 0.34 + 0.05
    assert ch["omega_meas"][0, late].mean() == pytest.approx(ch["omega"][0, late].mean(), abs=0.02)


# ------------------------------------------------------------------ physics of the closed loop


def test_ideal_loop_settles_at_the_hand_derived_operating_point():
    cfg = config(duration=12.0, settle=10.0, **IDEAL)
    ch, m = simulate_batch(cfg, 1)
    p = cfg.params
    i_ss, w_ss = 1.0, 5.0
    assert ch["i"][0, -1] == pytest.approx(i_ss, abs=1e-6)
    assert ch["omega"][0, -1] == pytest.approx(w_ss, rel=1e-5)
    # Eq. (4.13): with the integrators settled, V₁ is exactly the feed-forward bias.
    assert ch["v1"][0, -1] == pytest.approx(p.R * i_ss + p.K * w_ss, rel=1e-5)
    # Shaft balance K i₁ − K i₂ = b ω fixes the braking current, and its own circuit the V₂.
    i2 = i_ss - p.b * w_ss / p.K
    assert ch["v2"][0, -1] == pytest.approx(p.R * i2 - p.K * w_ss, rel=1e-5)
    assert abs(m["steady_state_error"][0]) < 1e-5
    assert m["speed_mean"][0] == pytest.approx(w_ss, rel=1e-5)


def test_linear_closed_loop_has_unit_dc_gain():
    # Integral action: zero steady-state error to a constant reference.
    for k in (1, 16):
        sys = linear_loop(config(controller={"filter_order": k}, **IDEAL))
        assert abs(sys.dcgain()) == pytest.approx(1.0, rel=1e-9)


def test_pi_discrete_step_response():
    # u[n] = kp e[n] + ki Σ_{j≤n} e[j] dt; for a unit step, u[n] = kp + ki dt (n + 1).
    kp, ki, dt = 10.0, 100.0, 1e-3
    n = np.arange(50)
    resp = control.forced_response(pi_discrete(kp, ki, dt), T=n * dt, U=np.ones(n.size))
    np.testing.assert_allclose(np.ravel(resp.outputs), kp + ki * dt * (n + 1), rtol=1e-12)


@pytest.mark.parametrize(
    ("frequency", "settle", "duration"),
    [(5.0, 4.0, 4.0 + 4 * 2 * math.pi / 5.0), (25.0, 4.0, 5.0), (100.0, 4.0, 5.0)],
)
def test_ideal_loop_frequency_response_matches_the_linear_model(
    frequency: float, settle: float, duration: float
):
    cfg = config(
        duration=duration,
        settle=settle,
        reference={"amplitude": 0.1, "frequency": frequency},
        **IDEAL,
    )
    ch, m = simulate_batch(cfg, 1)
    assert m["saturation_fraction"][0] < 0.01  # only the start-up transient saturates
    sys = linear_loop(cfg)
    assert is_stable(sys)
    g = np.ravel(control.frequency_response(sys, [frequency]).complex)[0]
    assert m["amplitude_ratio"][0] == pytest.approx(abs(g), rel=0.01)
    assert math.degrees(abs(m["phase_lag"][0] - (-np.angle(g)))) < 1.0
    # Independent fit of the recorded current, not the loop's running sums.
    t = time_axis(cfg)
    steady = t >= settle
    X = np.column_stack([np.ones(steady.sum()), np.sin(frequency * t[steady])])
    X = np.column_stack([X, np.cos(frequency * t[steady])])
    coef, *_ = np.linalg.lstsq(X, ch["i"][0, steady], rcond=None)
    fitted = complex(coef[1], coef[2]) / 0.1  # a sin + b cos = Im((a + jb) e^{jωt})
    assert abs(fitted) == pytest.approx(abs(g), rel=0.01)
    assert math.degrees(abs(np.angle(fitted / g))) < 1.0


@pytest.mark.parametrize("frequency", [5.0, 25.0, 100.0])
def test_single_rig_frequency_response_matches_the_linear_model(frequency: float):
    # Without the secondary the shaft spins up freely, so keep the current small enough
    # (ω → K i / b ≈ 11 rad/s, back-emf ≈ 5 V) for the driver never to saturate.
    cfg = config(
        rig="single",
        duration=5.0,
        settle=3.0,
        reference={"current": 0.05, "speed": 0.0, "amplitude": 0.02, "frequency": frequency},
        **IDEAL,
    )
    _, m = simulate_batch(cfg, 1)
    assert m["saturation_fraction"][0] == 0.0
    sys = linear_loop(cfg)
    assert is_stable(sys)
    g = np.ravel(control.frequency_response(sys, [frequency]).complex)[0]
    assert m["amplitude_ratio"][0] == pytest.approx(abs(g), rel=0.01)
    assert math.degrees(abs(m["phase_lag"][0] + np.angle(g))) < 1.0


def test_filtered_loop_frequency_response_matches_the_linear_model():
    k, w = 32, 25.0
    cfg = config(
        duration=5.0,
        settle=4.0,
        controller={"filter_order": k},
        reference={"amplitude": 0.1, "frequency": w},
        **IDEAL,
    )
    _, m = simulate_batch(cfg, 1)
    g = np.ravel(control.frequency_response(linear_loop(cfg), [w]).complex)[0]
    assert m["amplitude_ratio"][0] == pytest.approx(abs(g), rel=0.01)
    assert math.degrees(abs(m["phase_lag"][0] + np.angle(g))) < 1.0


def test_bandwidth_is_the_minus_3_db_crossing():
    cfg = config(**IDEAL)
    sys = linear_loop(cfg)
    wb = bandwidth(sys, cfg.dt)
    assert 0 < wb < math.pi / cfg.dt
    mag = np.abs(np.ravel(control.frequency_response(sys, [wb]).complex))[0]
    assert mag / abs(sys.dcgain()) == pytest.approx(10 ** (-3 / 20), rel=1e-3)
    below = np.geomspace(1e-2, 0.99 * wb, 200)
    mags = np.abs(np.ravel(control.frequency_response(sys, below).complex))
    assert np.all(mags / abs(sys.dcgain()) > 10 ** (-3 / 20))


def test_small_inductance_destabilises_the_unfiltered_loop():
    # With L = 1 mH the armature settles within one 1 ms sample (e^{−R·dt/L} ≈ 2e-4), so the
    # sampled loop is i[n+1] ≈ (kp/R)(r − i[n]): a pole near −kp/R = −1.2, outside the circle.
    small = config(motor={**TABLE_4_2_DICT, "L": 1e-3}, duration=3.0, settle=2.0, **IDEAL)
    default = config(duration=3.0, settle=2.0, **IDEAL)
    assert small.params.L == 1e-3
    assert default.params.L == 10e-3
    assert not is_stable(linear_loop(small))
    assert is_stable(linear_loop(default))
    poles = linear_loop(small).poles()
    assert np.abs(poles).max() == pytest.approx(10 / 8.35, rel=0.05)
    # The simulated loop agrees: a sustained (saturation-limited) oscillation against a
    # current that settles.
    ch_small, _ = simulate_batch(small, 1)
    ch_default, _ = simulate_batch(default, 1)
    assert np.std(ch_small["i"][0, -500:]) > 0.05
    assert np.std(ch_default["i"][0, -500:]) < 1e-3


# ----------------------------------------------------------------------------- validation


@pytest.mark.parametrize(
    "fields",
    [
        {"duration": 2.0, "settle": 2.0},
        {"duration": 1.0, "settle": 3.0},
        {"dt": math.nan},
        {"duration": math.nan},
        {"settle": math.nan},
        {"duration": math.inf},
        {"reference": {"current": math.nan}},
        {"reference": {"frequency": math.nan}},
        {"controller": {"kp": math.nan}},
        {"pwm": {"v_max": math.nan}},
        {"motor": {**TABLE_4_2_DICT, "R": math.nan}},
        {"sensor": {"noise_pp": math.nan}},
    ],
    ids=lambda f: repr(f)[:40],
)
def test_bad_configs_raise_config_error(fields: dict):
    with pytest.raises(ConfigError):
        parse_model(CurrentControlConfig, fields)


@pytest.mark.parametrize(
    "reference", [{}, {"amplitude": 0.1, "frequency": 5.0}], ids=["step", "sinusoid"]
)
@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")
def test_config_with_empty_steady_window_is_rejected(reference: dict):
    fields = {"duration": 2.0, "settle": 1.9995, "reference": reference}
    with pytest.raises(ConfigError):
        parse_model(CurrentControlConfig, fields)


def test_zero_step_has_no_rise_time():
    cfg = config(duration=0.5, settle=0.3, reference={"current": 0.0, "speed": 5.0})
    ch, m = simulate_batch(cfg, 1)
    assert np.isnan(rise_time(time_axis(cfg), ch["i"], 0.0, 0.0)[0])
    assert np.isnan(m["rise_time"][0])
    assert np.isnan(m["rise_time_feedback"][0])


def test_valid_config_round_trips():
    cfg = parse_model(CurrentControlConfig, {"duration": 2.0, "settle": 1.98})
    assert cfg.steps == 2000
