"""control/pwm.py: PWM duty quantisation and saturation, Eqs. (4.15)-(4.16), as properties."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from articula.control.pwm import pwm_counts, pwm_voltage, saturate

BITS = st.integers(1, 16)
V_MAX = st.floats(0.5, 48.0)
# Commanded voltage as a multiple of v_max, well past both rails.
SCALE = st.floats(-3.0, 3.0)


def applied(voltage: float, v_max: float, bits: int) -> float:
    """Mean voltage the driver puts on the motor for a commanded voltage."""
    return pwm_voltage(pwm_counts(voltage, v_max, bits), v_max, bits)


@settings(max_examples=50, deadline=None)
@given(scale=SCALE, v_max=V_MAX, bits=BITS)
def test_counts_fit_an_n_bit_register(scale: float, v_max: float, bits: int):
    counts = pwm_counts(scale * v_max, v_max, bits)
    assert isinstance(counts, int)
    assert abs(counts) <= 2**bits - 1


@settings(max_examples=50, deadline=None)
@given(scale=SCALE, v_max=V_MAX, bits=BITS)
def test_applied_never_exceeds_command_or_supply(scale: float, v_max: float, bits: int):
    v = scale * v_max
    out = applied(v, v_max, bits)
    assert abs(out) <= min(abs(v), v_max)
    # The H-bridge direction follows the sign of the command.
    assert out == 0.0 or math.copysign(1.0, out) == math.copysign(1.0, v)


@settings(max_examples=50, deadline=None)
@given(scale=st.floats(-1.0, 1.0, exclude_min=True, exclude_max=True), v_max=V_MAX, bits=BITS)
def test_quantisation_error_below_one_lsb_in_range(scale: float, v_max: float, bits: int):
    v = scale * v_max
    assume(abs(v) < v_max)
    lsb = v_max / 2**bits
    assert 0.0 <= abs(v) - abs(applied(v, v_max, bits)) < lsb


@pytest.mark.parametrize("bits", [1, 8, 10, 16])
def test_full_scale_is_clipped_to_register_maximum(bits: int):
    v_max = 12.0
    lsb = v_max / 2**bits
    for v in (v_max, 1.5 * v_max, 1e9):
        assert pwm_counts(v, v_max, bits) == 2**bits - 1
        assert pwm_counts(-v, v_max, bits) == -(2**bits - 1)
        assert applied(v, v_max, bits) == pytest.approx(v_max - lsb)


@settings(max_examples=50, deadline=None)
@given(scale=SCALE, v_max=V_MAX, bits=BITS)
def test_odd_symmetry(scale: float, v_max: float, bits: int):
    v = scale * v_max
    assume(v != 0.0)
    assert pwm_counts(-v, v_max, bits) == -pwm_counts(v, v_max, bits)
    assert applied(-v, v_max, bits) == -applied(v, v_max, bits)


def test_zero_of_either_sign_gives_zero_duty():
    assert pwm_counts(0.0, 12.0, 8) == 0
    assert pwm_counts(-0.0, 12.0, 8) == 0


@settings(max_examples=50, deadline=None)
@given(a=SCALE, b=SCALE, v_max=V_MAX, bits=BITS)
def test_monotone_non_decreasing(a: float, b: float, v_max: float, bits: int):
    lo, hi = sorted((a * v_max, b * v_max))
    assert pwm_counts(lo, v_max, bits) <= pwm_counts(hi, v_max, bits)
    assert applied(lo, v_max, bits) <= applied(hi, v_max, bits)


def test_monotone_on_a_dense_sweep():
    v_max, bits = 12.0, 8
    volts = np.linspace(-15.0, 15.0, 20001)
    counts = np.array([pwm_counts(v, v_max, bits) for v in volts])
    assert np.all(np.diff(counts) >= 0)
    # Every register value between the two full-scale ends is reached.
    assert set(counts) == set(range(-(2**bits - 1), 2**bits))


def test_eq_4_15_worked_values():
    # S = ⌊V / V_max · 2^N⌋ for N = 8, V_max = 12 V, by hand.
    assert pwm_counts(6.0, 12.0, 8) == 128
    assert pwm_counts(10.5925, 12.0, 8) == 225  # ⌊225.97⌋, the Fig. 4.5 bias voltage
    assert pwm_counts(0.04, 12.0, 8) == 0  # below one LSB of 46.9 mV
    assert pwm_counts(-0.05, 12.0, 8) == -1
    assert pwm_voltage(128, 12.0, 8) == pytest.approx(6.0)
    assert pwm_voltage(-255, 12.0, 8) == pytest.approx(-12.0 * 255 / 256)


@settings(max_examples=50, deadline=None)
@given(scale=SCALE, v_max=V_MAX)
def test_saturate_is_a_symmetric_clip(scale: float, v_max: float):
    v = scale * v_max
    out = saturate(v, v_max)
    assert out == float(np.clip(v, -v_max, v_max))
    assert -v_max <= out <= v_max
    if abs(v) <= v_max:
        assert out == v
