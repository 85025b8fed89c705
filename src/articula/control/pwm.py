"""PWM duty-cycle quantisation with saturation and H-bridge direction, Eqs. (4.15)-(4.16)."""

from __future__ import annotations

import math

from articula.numba_cache import jit


@jit(error_model="numpy")
def pwm_counts(voltage: float, v_max: float, bits: int) -> int:
    """Signed duty register value S[n] for a commanded voltage, Eq. (4.15).

    Args:
        voltage: commanded voltage; its sign selects the H-bridge direction [V].
        v_max: supply voltage, the voltage at full duty [V].
        bits: resolution N of the duty register.

    Returns:
        The signed duty count, |S| ≤ 2^N − 1.
    """
    magnitude = min(abs(voltage), v_max)  # Eq. (4.16), applied to |V|; the sign drives the H-bridge
    levels = 1 << bits
    counts = min(math.floor(magnitude / v_max * levels), levels - 1)  # Eq. (4.15); an N-bit
    # register holds at most 2^N − 1, so the book's closed range [0, 2^N] is cut at 2^N − 1.
    return counts if voltage >= 0 else -counts


@jit(error_model="numpy")
def pwm_voltage(counts: int, v_max: float, bits: int) -> float:
    """Mean voltage the H-bridge applies for a signed duty register value.

    Args:
        counts: signed duty register value S[n].
        v_max: supply voltage, the voltage at full duty [V].
        bits: resolution N of the duty register.

    Returns:
        The mean applied voltage [V].
    """
    return v_max * counts / (1 << bits)


@jit(error_model="numpy")
def saturate(voltage: float, v_max: float) -> float:
    """Voltage clipped to the driver's range [−v_max, v_max], Eq. (4.16) on both signs.

    Args:
        voltage: commanded voltage [V].
        v_max: supply voltage, the driver's limit [V].

    Returns:
        The clipped voltage [V].
    """
    return max(-v_max, min(v_max, voltage))
