"""tuning/response.py: E (2.7), M (2.5) and the step-response features tuners decide on."""

import numpy as np
import pytest

from articula.tuning.response import Response, step_features, tracking_error, tuning_cost


def test_tracking_error_and_tuning_cost_by_hand():
    t = np.array([0.0, 0.5, 1.0])
    ref = np.array([1.0, 1.0, 1.0])
    y = np.array([0.0, 0.5, 2.0])
    assert tracking_error(ref, y) == pytest.approx((1 + 0.5 + 1) / 3)  # Eq. (2.7)
    # e = 1, 0.5, -1; Δe/Δt = 0 (first sample), -1, -3: M = (1 + 1.5 + 4) / 3, Eq. (2.5)
    assert tuning_cost(t, ref, y) == pytest.approx(6.5 / 3)


def test_step_features_of_a_damped_cosine():
    # y = 1 - exp(-t) cos(2πt): extremes where tan(2πt) = -1/(2π), every 0.5 s from
    # t1 = 0.5 - atan(1/(2π))/(2π), each smaller by exp(-0.5).
    t = np.arange(0, 8, 1e-3)
    y = 1 - np.exp(-t) * np.cos(2 * np.pi * t)
    f = step_features(Response(t, np.ones_like(t), y), band=0.01)
    t1 = 0.5 - np.arctan(1 / (2 * np.pi)) / (2 * np.pi)
    assert f.overshoot == pytest.approx(-np.exp(-t1) * np.cos(2 * np.pi * t1), rel=1e-5)
    assert f.peak_times[:3] == pytest.approx([t1, t1 + 0.5, t1 + 1.0], abs=1e-3)
    assert f.peak_sizes[1] / f.peak_sizes[0] == pytest.approx(np.exp(-0.5), rel=1e-2)
    assert f.converging and f.period == pytest.approx(1.0, abs=1e-2)
    assert f.steady_state_error < 1e-3


def test_step_features_without_oscillation():
    t = np.arange(0, 5, 0.01)
    f = step_features(Response(t, np.full_like(t, 2.0), 1.5 * (1 - np.exp(-3 * t))), band=0.01)
    assert not f.oscillates and np.isnan(f.decay) and f.overshoot == 0.0
    assert f.steady_state_error == pytest.approx(0.5, abs=1e-3)
