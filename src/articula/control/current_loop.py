"""Closed-loop simulation of the chapter-4 current-control rigs, compiled with numba.

The primary motor runs the PI + feed-forward current controller, Eqs. (4.13)-(4.14), through
the PWM of Eqs. (4.15)-(4.16), on a current measured by the ACS712 and filtered by the moving
average of Eq. (4.17). On the dual rig the secondary runs the speed PI of Eq. (4.12). The rig
is linear between samples, so it advances by its exact zero-order-hold matrices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from articula.control.moving_average import moving_average_push
from articula.control.pwm import pwm_counts, pwm_voltage, saturate
from articula.plants.motor_rig import I_PRIMARY, OMEGA, THETA
from articula.plants.motor_sensors import encoder_count, read_current

CHANNELS = ("i", "i_meas", "i_fb", "omega", "omega_meas", "v1", "duty1", "v2")


@dataclass(frozen=True)
class LoopSettings:
    """Everything the compiled loop needs, as plain numbers: gains, sensors, PWM, sample time."""

    dt: float  # [s]
    v_bias: float  # [V] constant feed-forward of Eq. (4.13)
    kp: float  # [V/A]
    ki: float  # [V/(A·s)]
    filter_order: int
    dual: bool
    kp_speed: float  # [V·s/rad]
    ki_speed: float  # [V/rad]
    v_max: float  # [V]
    pwm_bits: int  # 0: ideal driver (saturation only)
    sensor_ideal: bool
    sensitivity: float  # [V/A]
    zero_voltage: float  # [V]
    noise_sigma: float  # [V]
    adc_bits: int
    adc_vref: float  # [V]
    encoder_cpr: int  # 0: ideal speed measurement
    encoder_window: int


def simulate_loop(
    Ad: np.ndarray,
    Bd: np.ndarray,
    settings: LoopSettings,
    i_ref: np.ndarray,
    omega_ref: float,
    noise: np.ndarray,
) -> dict[str, np.ndarray]:
    """Run a batch of closed loops; `noise` is (batch, steps) standard normals; returns channels.

    Every channel comes back as a (batch, steps) array sampled at the start of each step.
    """
    batch, steps = noise.shape
    out = np.empty((len(CHANNELS), batch, steps))
    s = settings
    _loop(
        Ad, Bd, np.ascontiguousarray(i_ref, dtype=float), float(omega_ref), noise, out,
        s.dt, s.v_bias, s.kp, s.ki, s.filter_order, s.dual, s.kp_speed, s.ki_speed,
        s.v_max, s.pwm_bits, s.sensor_ideal, s.sensitivity, s.zero_voltage, s.noise_sigma,
        s.adc_bits, s.adc_vref, s.encoder_cpr, s.encoder_window,
    )  # fmt: skip
    return dict(zip(CHANNELS, out, strict=True))


@njit(cache=True)
def _actuate(voltage: float, v_max: float, bits: int) -> tuple[float, float]:
    """(applied voltage [V], signed duty counts) for a commanded voltage."""
    if bits == 0:
        return saturate(voltage, v_max), 0.0
    counts = pwm_counts(voltage, v_max, bits)
    return pwm_voltage(counts, v_max, bits), float(counts)


@njit(cache=True)
def _loop(
    Ad, Bd, i_ref, omega_ref, noise, out,
    dt, v_bias, kp, ki, filter_order, dual, kp_speed, ki_speed,
    v_max, pwm_bits, sensor_ideal, sensitivity, zero_voltage, noise_sigma,
    adc_bits, adc_vref, encoder_cpr, encoder_window,
):  # fmt: skip
    batch, steps = noise.shape
    n_states = Ad.shape[0]
    x = np.zeros(n_states)
    x_next = np.zeros(n_states)
    filt = np.zeros(filter_order)
    counts = np.zeros(encoder_window, dtype=np.int64)
    for b in range(batch):
        x[:] = 0.0
        integral = 0.0
        integral_speed = 0.0
        for n in range(steps):
            i_true = x[I_PRIMARY]
            omega = x[OMEGA]
            if sensor_ideal:
                i_meas = i_true
            else:
                i_meas = read_current(
                    i_true, noise[b, n], sensitivity, zero_voltage, noise_sigma,
                    adc_bits, adc_vref,
                )  # fmt: skip
            i_fb = moving_average_push(filt, n, i_meas)  # Eq. (4.17) as a mean
            if encoder_cpr == 0:
                omega_meas = omega
            else:
                c = encoder_count(x[THETA], encoder_cpr)
                slot = n % encoder_window
                old = counts[slot] if n >= encoder_window else 0
                counts[slot] = c
                span = min(n, encoder_window) if n > 0 else 1
                omega_meas = (c - old) * 2.0 * np.pi / encoder_cpr / (span * dt)
            # Eq. (4.14) with e_I = i_ss − i, the stabilising sign (docs/deviations.md).
            error = i_ref[n] - i_fb
            integral += error * dt
            v1, duty1 = _actuate(v_bias + kp * error + ki * integral, v_max, pwm_bits)
            v2 = 0.0
            if dual:
                # Eq. (4.12) with e = ω_ref − ω; the secondary's reversed polarity means a
                # positive V₂ brakes the shaft, hence the minus sign.
                error_speed = omega_ref - omega_meas
                integral_speed += error_speed * dt
                v2, _ = _actuate(-(kp_speed * error_speed + ki_speed * integral_speed),
                                 v_max, pwm_bits)  # fmt: skip
            out[0, b, n] = i_true
            out[1, b, n] = i_meas
            out[2, b, n] = i_fb
            out[3, b, n] = omega
            out[4, b, n] = omega_meas
            out[5, b, n] = v1
            out[6, b, n] = duty1
            out[7, b, n] = v2
            for r in range(n_states):
                acc = Bd[r, 0] * v1 + Bd[r, 1] * v2
                for c2 in range(n_states):
                    acc += Ad[r, c2] * x[c2]
                x_next[r] = acc
            x[:] = x_next
    return out
