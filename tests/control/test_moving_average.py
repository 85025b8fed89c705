"""control/moving_average.py: the moving-average filter of Eq. (4.17), a mean of the last k samples
(zero history), vectorised and as a compiled ring buffer."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from articula.control.moving_average import moving_average, moving_average_push
from articula.errors import ConfigError

SAMPLES = st.lists(
    st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False), min_size=1, max_size=120
)
ORDERS = st.integers(1, 40)


def oracle(x: np.ndarray, k: int) -> np.ndarray:
    """np.mean over the last k samples, the samples before the start being zero."""
    padded = np.concatenate([np.zeros(k - 1), x])
    return np.array([np.mean(padded[n : n + k]) for n in range(len(x))])


def push_all(buffer: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Feed the columns of x (steps, batch) through the compiled ring buffer, step by step."""
    out = np.full(x.shape, np.nan)
    means = np.empty(x.shape[1])
    for n in range(x.shape[0]):
        moving_average_push(buffer, n, np.ascontiguousarray(x[n]), means)
        out[n] = means
    return out


@settings(max_examples=50, deadline=None)
@given(samples=SAMPLES, k=ORDERS, batch=st.integers(1, 5))
def test_ring_buffer_equals_mean_of_last_k(samples: list[float], k: int, batch: int):
    # Each column of the batch gets a different signal: shifted, scaled copies.
    base = np.array(samples)
    x = np.stack([base * (c + 1) - 7.0 * c for c in range(batch)], axis=1)
    buffer = np.zeros((k, batch))
    out = push_all(buffer, x)
    for c in range(batch):
        np.testing.assert_allclose(out[:, c], oracle(x[:, c], k), rtol=1e-12, atol=1e-9)


@settings(max_examples=50, deadline=None)
@given(samples=SAMPLES, k=ORDERS)
def test_vectorised_filter_equals_mean_of_last_k(samples: list[float], k: int):
    x = np.array(samples)
    np.testing.assert_allclose(moving_average(x, k), oracle(x, k), rtol=1e-9, atol=1e-9)


def test_start_up_ramps_from_zero_history():
    # A motor at rest has drawn 0 A before the start: a step reaches its value after k samples.
    k = 5
    out = push_all(np.zeros((k, 1)), np.full((8, 1), 2.0))[:, 0]
    np.testing.assert_allclose(out, [0.4, 0.8, 1.2, 1.6, 2.0, 2.0, 2.0, 2.0])


def test_vectorised_filter_works_along_last_axis():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(3, 4, 50))
    out = moving_average(x, 7)
    assert out.shape == x.shape
    for idx in np.ndindex(3, 4):
        np.testing.assert_allclose(out[idx], oracle(x[idx], 7), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("k", [1, 2, 16, 300])
def test_unit_dc_gain(k: int):
    x = np.full(400, 3.7)
    np.testing.assert_allclose(moving_average(x, k)[k - 1 :], 3.7, rtol=1e-12)
    pushed = push_all(np.zeros((k, 2)), np.full((400, 2), 3.7))
    np.testing.assert_allclose(pushed[k - 1 :], 3.7, rtol=1e-12)
    # The impulse response (once the start-up is past) sums to one.
    impulse = np.zeros(2 * k + 10)
    impulse[k] = 1.0
    assert moving_average(impulse, k)[k:].sum() == pytest.approx(1.0)


def test_order_one_is_identity():
    x = np.random.default_rng(2).normal(size=64)
    np.testing.assert_allclose(moving_average(x, 1), x, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(push_all(np.zeros((1, 1)), x[:, None])[:, 0], x)


@pytest.mark.parametrize("order", [0, -1, -10])
def test_order_below_one_raises_config_error(order: int):
    with pytest.raises(ConfigError) as err:
        moving_average(np.ones(10), order)
    assert err.value.field == "filter_order"


def test_mean_of_last_k_attenuates_a_sinusoid_like_a_dirichlet_kernel():
    # Steady-state gain of a k-sample mean at ω: |sin(kωT/2) / (k sin(ωT/2))|.
    k, dt, w = 16, 1e-3, 150.0
    t = np.arange(4000) * dt
    y = moving_average(np.sin(w * t), k)[1000:]
    expected = abs(np.sin(k * w * dt / 2) / (k * np.sin(w * dt / 2)))
    assert (y.max() - y.min()) / 2 == pytest.approx(expected, rel=2e-3)
