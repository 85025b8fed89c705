"""tests/oracles.py: the trace-based rise time and sinusoid fit against analytic responses."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.oracles import rise_time, sinusoid_fit


@settings(max_examples=50, deadline=None)
@given(
    tau=st.floats(1e-3, 1.0),
    samples_per_tau=st.floats(5.0, 200.0),
    start=st.floats(-5.0, 5.0),
    step=st.one_of(st.floats(-10.0, -0.01), st.floats(0.01, 10.0)),
)
def test_rise_time_of_first_order_step_is_tau_ln9(
    tau: float, samples_per_tau: float, start: float, step: float
):
    # y = y0 + Δ (1 − e^{−t/τ}): 10 % at τ ln(10/9), 90 % at τ ln 10, so t90 − t10 = τ ln 9.
    dt = tau / samples_per_tau
    t = np.arange(int(8 * samples_per_tau) + 1) * dt
    y = start + step * (1.0 - np.exp(-t / tau))
    rt = rise_time(t, y, start=start, target=start + step)
    assert rt.shape == (1,)
    assert abs(rt[0] - tau * math.log(9.0)) <= dt * (1 + 1e-9)


def test_rise_time_rows_are_independent():
    dt = 1e-3
    t = np.arange(3000) * dt
    taus = np.array([0.01, 0.05, 0.2])
    y = 1.0 - np.exp(-t[None, :] / taus[:, None])
    rt = rise_time(t, y, start=0.0, target=1.0)
    np.testing.assert_allclose(rt, taus * math.log(9.0), atol=dt)


def test_rise_time_nan_when_target_never_reached():
    t = np.arange(100) * 0.01
    y = np.vstack([np.full(100, 0.5), 1.0 - np.exp(-t / 0.05)])
    rt = rise_time(t, y, start=0.0, target=1.0)
    assert math.isnan(rt[0])
    assert rt[1] == pytest.approx(0.05 * math.log(9.0), abs=0.01)
    # No step at all: undefined.
    assert math.isnan(rise_time(t, np.ones(100), start=1.0, target=1.0)[0])


def test_rise_time_of_a_ramp():
    # y = t/T reaches 10 % at 0.1 T and 90 % at 0.9 T: rise time 0.8 T.
    dt, T = 1e-3, 0.5
    t = np.arange(1000) * dt
    rt = rise_time(t, np.minimum(t / T, 1.0), start=0.0, target=1.0)
    assert rt[0] == pytest.approx(0.8 * T, abs=dt)


@settings(max_examples=50, deadline=None)
@given(
    amplitude=st.floats(0.01, 10.0),
    phase=st.floats(-math.pi + 1e-3, math.pi - 1e-3),
    frequency=st.floats(1.0, 300.0),
    offset=st.floats(-5.0, 5.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_sinusoid_fit_recovers_amplitude_and_phase(
    amplitude: float, phase: float, frequency: float, offset: float, seed: int
):
    dt = 1e-3
    t = 0.7 + np.arange(4000) * dt  # fit window need not start at zero
    noise_sigma = 0.1 * amplitude
    rng = np.random.default_rng(seed)
    y = offset + amplitude * np.sin(frequency * t + phase) + rng.normal(0, noise_sigma, t.size)
    a, phi = sinusoid_fit(t, y, frequency)
    # Least-squares standard error of each quadrature is ≈ σ·sqrt(2/N); allow 6σ.
    tol = 6 * noise_sigma * math.sqrt(2.0 / t.size)
    assert a[0] == pytest.approx(amplitude, abs=tol)
    wrapped = (phi[0] - phase + math.pi) % (2 * math.pi) - math.pi
    assert abs(wrapped) <= tol / amplitude


def test_sinusoid_fit_rows_and_sign_of_phase():
    t = np.arange(2000) * 1e-3
    w = 25.0
    y = np.vstack(
        [
            np.sin(w * t),
            2.0 * np.cos(w * t),  # leads by +90°
            0.5 * np.sin(w * t - 0.3) + 1.0,  # lags by 0.3 rad
        ]
    )
    a, phi = sinusoid_fit(t, y, w)
    np.testing.assert_allclose(a, [1.0, 2.0, 0.5], atol=1e-9)
    np.testing.assert_allclose(phi, [0.0, math.pi / 2, -0.3], atol=1e-9)
