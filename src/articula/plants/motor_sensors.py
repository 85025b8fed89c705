"""Sensors of the chapter-4 rigs: ACS712-5A Hall current sensor on a 10-bit ADC, and an encoder."""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field, model_validator

from articula.numba_cache import jit
from articula.validation import NonNegative, Positive, StrictModel


class CurrentSensorParams(StrictModel):
    """ACS712-5A read by the Arduino's ADC; `ideal` bypasses noise and quantisation.

    Attributes:
        ideal: read the true current (no noise, no quantisation).
        sensitivity: output volts per ampere [V/A] (ACS712-5A datasheet).
        zero_voltage: output at 0 A [V]; must lie below adc_vref.
        noise_pp: peak-to-peak output noise [V] (taken as 6σ).
        adc_bits: resolution of the ADC [bits].
        adc_vref: ADC reference voltage, its full scale [V].
    """

    ideal: bool = False
    sensitivity: Positive = 0.185
    zero_voltage: Positive = 2.5
    noise_pp: NonNegative = 0.021
    adc_bits: Annotated[int, Field(ge=1, le=24)] = 10
    adc_vref: Positive = 5.0

    @model_validator(mode="after")
    def _zero_inside_adc_range(self) -> CurrentSensorParams:
        if self.zero_voltage >= self.adc_vref:
            raise ValueError(
                f"zero_voltage ({self.zero_voltage} V) must lie below adc_vref ({self.adc_vref} V)"
            )
        return self

    @property
    def noise_sigma(self) -> float:
        """Standard deviation [V] of the output noise, taking peak-to-peak as 6σ."""
        return self.noise_pp / 6.0


class EncoderParams(StrictModel):
    """Shaft encoder; speed is the count difference over a window of samples.

    Attributes:
        ideal: measure the true speed (no counting).
        counts_per_rev: encoder counts per shaft revolution.
        window: samples over which the count difference gives the speed (50 ms at 1 kHz).
    """

    ideal: bool = False
    counts_per_rev: Annotated[int, Field(ge=1, le=1_000_000_000)] = 375
    window: Annotated[int, Field(ge=1, le=100_000)] = 50


@jit(error_model="numpy")
def adc_code(
    current: float,
    noise: float,
    sensitivity: float,
    zero_voltage: float,
    noise_sigma: float,
    adc_bits: int,
    adc_vref: float,
) -> int:
    """The ADC's code for the sensor's output at `current` [A]; `noise` is a standard normal.

    Args:
        current: true current through the sensor [A].
        noise: a standard normal draw, scaled by `noise_sigma`.
        sensitivity: sensor output per ampere [V/A].
        zero_voltage: sensor output at 0 A [V].
        noise_sigma: standard deviation of the output noise [V].
        adc_bits: ADC resolution [bits].
        adc_vref: ADC reference voltage [V].

    Returns:
        The code, floored and clipped to [0, 2^adc_bits − 1].
    """
    volts = zero_voltage + sensitivity * current + noise_sigma * noise
    levels = 1 << adc_bits
    return min(max(math.floor(volts / adc_vref * levels), 0), levels - 1)


@jit(error_model="numpy")
def read_current(
    current: float,
    noise: float,
    sensitivity: float,
    zero_voltage: float,
    noise_sigma: float,
    adc_bits: int,
    adc_vref: float,
) -> float:
    """Current [A] the firmware computes from one ADC sample; `noise` is a standard normal draw.

    Args:
        current: true current through the sensor [A].
        noise: a standard normal draw, scaled by `noise_sigma`.
        sensitivity: sensor output per ampere [V/A].
        zero_voltage: sensor output at 0 A [V].
        noise_sigma: standard deviation of the output noise [V].
        adc_bits: ADC resolution [bits].
        adc_vref: ADC reference voltage [V].

    Returns:
        The measured current [A], reconstructed at the middle of the ADC step.
    """
    code = adc_code(current, noise, sensitivity, zero_voltage, noise_sigma, adc_bits, adc_vref)
    levels = 1 << adc_bits
    # Mid-step reconstruction: the firmware's estimate is unbiased for a dithered input.
    return ((code + 0.5) * adc_vref / levels - zero_voltage) / sensitivity


@jit(error_model="numpy")
def encoder_count(theta: float, counts_per_rev: int) -> int:
    """Integer count of an incremental encoder at shaft angle θ [rad].

    Args:
        theta: shaft angle θ [rad].
        counts_per_rev: encoder counts per revolution.

    Returns:
        The count, floor(θ · counts_per_rev / 2π).
    """
    return math.floor(theta * counts_per_rev / (2.0 * math.pi))
