"""loops/motor_current_linear.py: the linearised current loop against the compiled one and
closed forms (DC gain, PI step, frequency responses, bandwidth, stability), and its filter
against the time-domain moving average."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest

from articula.control.moving_average import moving_average
from articula.experiments.motor import (
    CurrentControlConfig,
    loop_settings,
    simulate_batch,
    time_axis,
)
from articula.loops.motor_current_linear import (
    bandwidth,
    closed_loop,
    is_stable,
    moving_average_tf,
    pi_discrete,
)
from articula.plants.motor_rig import discretize, rig_matrices
from tests.loops.helpers import IDEAL, config


@pytest.mark.parametrize("k", [1, 3, 16])
def test_linear_model_filter_matches_the_time_domain_filter(k: int):
    dt = 1e-3
    steps = 60
    u = np.random.default_rng(k).normal(size=steps)
    resp = control.forced_response(moving_average_tf(k, dt), T=np.arange(steps) * dt, U=u)
    # Both start from zero history, so they agree from the first sample.
    np.testing.assert_allclose(np.ravel(resp.outputs), moving_average(u, k), atol=1e-12)


TABLE_4_2_DICT = {"R": 8.35, "K": 0.4485, "b": 0.002, "J": 0.1}


def linear_loop(cfg: CurrentControlConfig) -> control.StateSpace:
    Ad, Bd = discretize(*rig_matrices(cfg.params, cfg.rig == "dual"), cfg.dt)
    return closed_loop(Ad, Bd, loop_settings(cfg))


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
