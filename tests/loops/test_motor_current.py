"""loops/motor_current.py: the compiled current loop against oracles (moving average, PWM,
control laws, ZOH rig, encoder) and the physics of the closed loop. Configs are built the way
users build them, through the motor.current experiment's config."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import cont2discrete, dlsim

from articula.control.moving_average import moving_average
from articula.experiments.motor import (
    CurrentControlConfig,
    simulate_batch,
)
from articula.plants.motor_rig import rig_matrices
from tests.loops.helpers import IDEAL, config


def noisy_config(**extra) -> CurrentControlConfig:
    """The book's unfiltered-or-filtered rig with every non-ideality on, kept short."""
    return config(duration=0.6, settle=0.3, **extra)


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


def test_encoder_speed_estimate_tracks_the_shaft_in_steady_state():
    cfg = config(seed=0, duration=6.0, settle=4.0, sensor={"ideal": True})
    ch, _ = simulate_batch(cfg, 1)
    late = slice(4000, None)
    # One count over the 50-sample window is 2π/375/0.05 = 0.335 rad/s.
    assert np.abs(ch["omega_meas"][0, late] - ch["omega"][0, late]).max() < 0.34 + 0.05
    assert ch["omega_meas"][0, late].mean() == pytest.approx(ch["omega"][0, late].mean(), abs=0.02)


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
