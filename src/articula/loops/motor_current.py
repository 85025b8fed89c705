"""Closed-loop simulation of the chapter-4 current-control rigs, compiled with numba.

The primary motor runs the PI + feed-forward current controller, Eqs. (4.13)-(4.14), through
the PWM of Eqs. (4.15)-(4.16), on a current measured by the ACS712 and filtered by the moving
average of Eq. (4.17). On the dual rig the secondary runs the speed PI of Eq. (4.12). The rig
is linear between samples, so it advances by its exact zero-order-hold matrices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from articula.control.moving_average import moving_average_push
from articula.control.pwm import pwm_counts, pwm_voltage, saturate
from articula.numba_cache import jit
from articula.plants.motor_rig import I_PRIMARY, OMEGA, THETA
from articula.plants.motor_sensors import encoder_count, read_current

CHANNELS = ("i", "i_meas", "i_fb", "omega", "omega_meas", "v1", "duty1", "v2")
# Running sums the loop keeps per trial, so metrics need no stored trace (see loop_metrics).
SUMS = (
    "error",
    "error_sq",
    "noise_sq",
    "omega",
    "saturated",
    "t10",
    "t90",
    "t10_fb",
    "t90_fb",
    "i",
    "i_sin",
    "i_cos",
)


@dataclass(frozen=True)
class LoopSettings:
    """Everything the compiled loop needs, as plain numbers: gains, sensors, PWM, sample time.

    Attributes:
        dt: control period [s].
        v_bias: constant feed-forward voltage of Eq. (4.13) [V].
        kp: proportional gain of the current PI, Eq. (4.14) [V/A].
        ki: integral gain of the current PI [V/(A·s)].
        filter_order: length of the current's moving average, Eq. (4.17) [samples].
        dual: the dual rig, whose secondary motor runs the speed PI of Eq. (4.12).
        kp_speed: proportional gain of the speed PI [V·s/rad].
        ki_speed: integral gain of the speed PI [V/rad].
        v_max: supply voltage of the drivers, the largest |V| [V].
        pwm_bits: PWM resolution [bits]; 0: ideal driver (saturation only).
        sensor_ideal: read the true current (no noise, no ADC).
        sensitivity: current sensor output per ampere [V/A].
        zero_voltage: current sensor output at 0 A [V].
        noise_sigma: standard deviation of the current sensor's output noise [V].
        adc_bits: ADC resolution [bits].
        adc_vref: ADC reference voltage [V].
        encoder_cpr: encoder counts per revolution; 0: ideal speed measurement.
        encoder_window: samples over which the encoder's count difference gives the speed.
    """

    dt: float
    v_bias: float
    kp: float
    ki: float
    filter_order: int
    dual: bool
    kp_speed: float
    ki_speed: float
    v_max: float
    pwm_bits: int
    sensor_ideal: bool
    sensitivity: float
    zero_voltage: float
    noise_sigma: float
    adc_bits: int
    adc_vref: float
    encoder_cpr: int
    encoder_window: int


@dataclass(frozen=True)
class MetricWindow:
    """What the loop's running sums need: where steady state starts and what a rise is.

    Attributes:
        settle_index: first sample of the steady-state window.
        rise_target: step target for the 10-90 % rise times [A]; NaN: no rise time.
        frequency: frequency of the sinusoidal reference [rad/s]; 0: no sinusoid fit.
    """

    settle_index: int
    rise_target: float
    frequency: float


def simulate_loop(
    Ad: np.ndarray,
    Bd: np.ndarray,
    settings: LoopSettings,
    window: MetricWindow,
    i_ref: np.ndarray,
    omega_ref: float,
    noise: np.ndarray,
    record: bool = True,
) -> tuple[dict[str, np.ndarray] | None, dict[str, np.ndarray]]:
    """Run a batch of closed loops; `noise` is (batch, steps) standard normals.

    Args:
        Ad: ZOH state matrix of the rig (motor_rig.discretize), shape (n, n).
        Bd: ZOH input matrix of the rig for [V₁, V₂], shape (n, 2).
        settings: gains, sensors, PWM and control period of the loop.
        window: steady-state start, rise target and sinusoid frequency of the running sums.
        i_ref: current reference at each step, shape (steps,) [A].
        omega_ref: speed reference of the dual rig's speed loop [rad/s].
        noise: standard normal draws of the current sensor, shape (batch, steps).
        record: keep the channels; False saves the memory of long Monte Carlo batches.

    Returns:
        channels: name in CHANNELS -> (batch, steps) array sampled at the start of each
            step (i, i_meas, i_fb [A], omega, omega_meas [rad/s], v1 [V], duty1 [counts],
            v2 [V]); None when `record` is False.
        sums: name in SUMS -> (batch,) array; sums over the steady-state window (error,
            error_sq, noise_sq, omega, i, i_sin, i_cos), saturated steps over the whole run,
            and the 10 % / 90 % crossing times t10, t90, t10_fb, t90_fb [s] (NaN: none).
    """
    batch, steps = noise.shape
    # Time-major layout: the compiled loop walks the batch innermost, where it vectorises.
    out = np.empty((len(CHANNELS), steps if record else 0, batch))
    sums = np.zeros((len(SUMS), batch))
    t = np.arange(steps) * settings.dt
    s = settings
    _loop(
        Ad,
        Bd,
        np.ascontiguousarray(i_ref, dtype=float),
        float(omega_ref),
        np.ascontiguousarray(noise.T),
        out,
        sums,
        record,
        window.settle_index,
        window.rise_target,
        np.sin(window.frequency * t),
        np.cos(window.frequency * t),
        s.dt,
        s.v_bias,
        s.kp,
        s.ki,
        s.filter_order,
        s.dual,
        s.kp_speed,
        s.ki_speed,
        s.v_max,
        s.pwm_bits,
        s.sensor_ideal,
        s.sensitivity,
        s.zero_voltage,
        s.noise_sigma,
        s.adc_bits,
        s.adc_vref,
        s.encoder_cpr,
        s.encoder_window,
    )
    channels = {name: out[c].T for c, name in enumerate(CHANNELS)} if record else None
    return channels, dict(zip(SUMS, sums, strict=True))


@jit(error_model="numpy")
def _actuate(voltage: float, v_max: float, bits: int) -> tuple[float, float]:
    """(applied voltage [V], signed duty counts) for a commanded voltage."""
    if bits == 0:
        return saturate(voltage, v_max), 0.0
    counts = pwm_counts(voltage, v_max, bits)
    return pwm_voltage(counts, v_max, bits), float(counts)


@jit(error_model="numpy")
def _loop(
    Ad,
    Bd,
    i_ref,
    omega_ref,
    noise,
    out,
    sums,
    record,
    settle_index,
    rise_target,
    sin_t,
    cos_t,
    dt,
    v_bias,
    kp,
    ki,
    filter_order,
    dual,
    kp_speed,
    ki_speed,
    v_max,
    pwm_bits,
    sensor_ideal,
    sensitivity,
    zero_voltage,
    noise_sigma,
    adc_bits,
    adc_vref,
    encoder_cpr,
    encoder_window,
):
    steps, batch = noise.shape
    n_states = Ad.shape[0]
    x = np.zeros((n_states, batch))
    x_next = np.zeros((n_states, batch))
    i_true = np.empty(batch)
    i_meas = np.empty(batch)
    i_fb = np.empty(batch)
    i_true_fb = np.empty(batch)
    v1 = np.empty(batch)
    v2 = np.zeros(batch)
    integral = np.zeros(batch)
    integral_speed = np.zeros(batch)
    filt = np.zeros((filter_order, batch))
    filt_true = np.zeros((filter_order, batch))
    counts = np.zeros((encoder_window, batch), dtype=np.int64)
    v_full = v_max if pwm_bits == 0 else pwm_voltage((1 << pwm_bits) - 1, v_max, pwm_bits)
    sums[5:9, :] = np.nan
    # Each pass below is a loop over the batch with no dependence between trials.
    for n in range(steps):
        t = n * dt
        for b in range(batch):
            i_true[b] = x[I_PRIMARY, b]
            if sensor_ideal:
                i_meas[b] = i_true[b]
            else:
                i_meas[b] = read_current(
                    i_true[b],
                    noise[n, b],
                    sensitivity,
                    zero_voltage,
                    noise_sigma,
                    adc_bits,
                    adc_vref,
                )
        moving_average_push(filt, n, i_meas, i_fb)  # Eq. (4.17) as a mean
        # The same filter on the true current separates sensor noise from filter lag.
        moving_average_push(filt_true, n, i_true, i_true_fb)
        slot = n % encoder_window
        span = min(n, encoder_window) if n > 0 else 1
        for b in range(batch):
            omega = x[OMEGA, b]
            if encoder_cpr == 0:
                omega_meas = omega
            else:
                c = encoder_count(x[THETA, b], encoder_cpr)
                old = counts[slot, b] if n >= encoder_window else 0
                counts[slot, b] = c
                omega_meas = (c - old) * 2.0 * np.pi / encoder_cpr / (span * dt)
            # Eq. (4.14) with e_I = i_ss − i, the stabilising sign (docs/deviations.md).
            error = i_ref[n] - i_fb[b]
            integral[b] += error * dt
            v1[b], duty1 = _actuate(v_bias + kp * error + ki * integral[b], v_max, pwm_bits)
            if dual:
                # Eq. (4.12) with e = ω_ref − ω; the secondary's reversed polarity means a
                # positive V₂ brakes the shaft, hence the minus sign.
                error_speed = omega_ref - omega_meas
                integral_speed[b] += error_speed * dt
                v2[b], _ = _actuate(
                    -(kp_speed * error_speed + ki_speed * integral_speed[b]), v_max, pwm_bits
                )
            if record:
                out[0, n, b] = i_true[b]
                out[1, n, b] = i_meas[b]
                out[2, n, b] = i_fb[b]
                out[3, n, b] = omega
                out[4, n, b] = omega_meas
                out[5, n, b] = v1[b]
                out[6, n, b] = duty1
                out[7, n, b] = v2[b]
            sums[4, b] += abs(v1[b]) >= v_full
            if n >= settle_index:
                e = i_true[b] - i_ref[n]
                sums[0, b] += e
                sums[1, b] += e * e
                d = i_fb[b] - i_true_fb[b]
                sums[2, b] += d * d
                sums[3, b] += omega
                sums[9, b] += i_true[b]
                sums[10, b] += i_true[b] * sin_t[n]
                sums[11, b] += i_true[b] * cos_t[n]
            elif rise_target == rise_target:  # not NaN: first 10 % and 90 % crossings
                for row, y in ((5, i_true[b]), (7, i_fb[b])):
                    frac = y / rise_target
                    if frac >= 0.1 and sums[row, b] != sums[row, b]:
                        sums[row, b] = t
                    if frac >= 0.9 and sums[row + 1, b] != sums[row + 1, b]:
                        sums[row + 1, b] = t
        for r in range(n_states):
            for b in range(batch):
                x_next[r, b] = Bd[r, 0] * v1[b] + Bd[r, 1] * v2[b]
            for c2 in range(n_states):
                for b in range(batch):
                    x_next[r, b] += Ad[r, c2] * x[c2, b]
        x, x_next = x_next, x
