"""plants/motor_sensors.py: the ACS712 current sensor on an n-bit ADC (quantisation, saturation,
dithering noise) and the encoder count."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from articula.plants.motor_sensors import CurrentSensorParams, encoder_count, read_current


def _read(current: float, sensor: CurrentSensorParams, noise: float = 0.0) -> float:
    return read_current(
        current,
        noise,
        sensor.sensitivity,
        sensor.zero_voltage,
        sensor.noise_sigma,
        sensor.adc_bits,
        sensor.adc_vref,
    )


@settings(max_examples=50, deadline=None)
@given(current=st.floats(-13.0, 13.0), bits=st.integers(6, 16))
def test_read_current_without_noise_within_half_an_adc_step(current: float, bits: int):
    sensor = CurrentSensorParams(adc_bits=bits)
    step = sensor.adc_vref / 2**bits
    assert abs(_read(current, sensor) - current) <= 0.5 * step / sensor.sensitivity + 1e-12


def test_read_current_acs712_on_10_bit_adc_values():
    sensor = CurrentSensorParams()
    # One ADC step is 5 V / 1024 = 4.88 mV, i.e. 26.4 mA at 185 mV/A.
    step_amps = 5.0 / 1024 / 0.185
    assert abs(_read(0.0, sensor)) <= 0.5 * step_amps
    assert abs(_read(1.0, sensor) - 1.0) <= 0.5 * step_amps
    # Readings are quantised: differences are whole ADC steps.
    readings = np.array([_read(c, sensor) for c in np.linspace(-2, 2, 401)])
    steps = np.diff(readings) / step_amps
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-9)
    assert np.all(np.diff(readings) >= 0)


def test_read_current_saturates_at_the_adc_rails():
    sensor = CurrentSensorParams()
    # The output can span only 0..5 V: −13.5 A .. +13.5 A for a 2.5 V zero and 185 mV/A.
    hi, lo = _read(100.0, sensor), _read(-100.0, sensor)
    assert _read(14.0, sensor) == hi == _read(1e6, sensor)
    assert _read(-14.0, sensor) == lo == _read(-1e6, sensor)
    assert hi <= (5.0 - 2.5) / 0.185
    assert lo >= (0.0 - 2.5) / 0.185
    step_amps = 5.0 / 1024 / 0.185
    assert hi == pytest.approx((5.0 - 2.5) / 0.185, abs=step_amps)
    assert lo == pytest.approx(-2.5 / 0.185, abs=step_amps)


def test_read_current_noise_dithers_to_an_unbiased_mean():
    sensor = CurrentSensorParams()
    rng = np.random.default_rng(0)
    draws = rng.standard_normal(20000)
    step_amps = 5.0 / 1024 / 0.185
    for current in (0.3, 1.0, 1.0 + 0.37 * step_amps):
        readings = np.array([_read(current, sensor, float(z)) for z in draws])
        assert readings.mean() == pytest.approx(current, abs=0.05 * step_amps)
        # Spread: the sensor's σ (noise_pp / 6 = 3.5 mV → 18.9 mA) plus quantisation.
        sigma = 0.021 / 6 / 0.185
        expected = math.sqrt(sigma**2 + step_amps**2 / 12)
        assert readings.std() == pytest.approx(expected, rel=0.1)


@pytest.mark.parametrize("cpr", [1, 375, 4096])
def test_encoder_count_floors(cpr: int):
    per_count = 2 * math.pi / cpr
    for k in (-5, -1, 0, 1, 7, 3 * cpr + 2):
        for frac in (0.01, 0.5, 0.99):
            assert encoder_count((k + frac) * per_count, cpr) == k
    assert encoder_count(0.0, cpr) == 0
    assert encoder_count(-1e-9, cpr) == -1  # floor, not truncation toward zero
    assert encoder_count(2 * math.pi * 3 + 0.1 * per_count, cpr) == 3 * cpr
