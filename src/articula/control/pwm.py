"""PWM duty-cycle quantisation with saturation and H-bridge direction, Eqs. (4.15)-(4.16)."""

from __future__ import annotations

import math

from articula.numba_cache import jit


@jit(error_model="numpy")
def pwm_counts(voltage: float, v_max: float, bits: int) -> int:
    """Signed duty register value S[n] for a commanded voltage [V], Eq. (4.15)."""
    magnitude = min(abs(voltage), v_max)  # Eq. (4.16), applied to |V|; the sign drives the H-bridge
    levels = 1 << bits
    counts = min(math.floor(magnitude / v_max * levels), levels - 1)  # Eq. (4.15); an N-bit
    # register holds at most 2^N − 1, so the book's closed range [0, 2^N] is cut at 2^N − 1.
    return counts if voltage >= 0 else -counts


@jit(error_model="numpy")
def pwm_voltage(counts: int, v_max: float, bits: int) -> float:
    """Mean voltage [V] the H-bridge applies for a signed duty register value."""
    return v_max * counts / (1 << bits)


@jit(error_model="numpy")
def saturate(voltage: float, v_max: float) -> float:
    """Voltage [V] clipped to the driver's range [−v_max, v_max], Eq. (4.16) on both signs."""
    return max(-v_max, min(v_max, voltage))
