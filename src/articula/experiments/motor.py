"""Chapter 4 experiment: PI + feed-forward current control on the single or dual motor rig."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from articula.loops.motor_current import LoopSettings, MetricWindow, simulate_loop
from articula.plants.dc_motor import PRESETS, MotorParams, feedforward_voltage
from articula.plants.motor_rig import discretize, rig_matrices
from articula.plants.motor_sensors import CurrentSensorParams, EncoderParams
from articula.runs.registry import Experiment, Progress, Result
from articula.validation import Finite, NonNegative, Positive, Seed, StrictModel, field_error

MAX_STEPS = 10_000_000
MIN_STEADY_SAMPLES = 10


class CurrentReference(StrictModel):
    """Current reference i_ref(t) = current + amplitude·sin(frequency·t) and the shaft speed.

    Attributes:
        current: constant part i_ss of the reference [A].
        speed: shaft speed ω_ss the feed-forward of Eq. (4.13) assumes, held by the
            secondary motor on the dual rig [rad/s].
        amplitude: amplitude of the sinusoidal part [A]; 0: a constant reference.
        frequency: angular frequency of the sinusoidal part [rad/s].
    """

    current: Finite = 1.0
    speed: Finite = 5.0
    amplitude: NonNegative = 0.0
    frequency: NonNegative = 0.0


class CurrentControllerConfig(StrictModel):
    """PI gains of Eq. (4.14) and the moving-average order of Eq. (4.17) (1 = unfiltered).

    Attributes:
        kp: proportional gain K_p, Eq. (4.14) [V/A].
        ki: integral gain K_i, Eq. (4.14) [V/(A·s)].
        filter_order: length of the moving average on the measured current, Eq. (4.17)
            [samples]; 1: unfiltered.
    """

    kp: NonNegative = 10.0
    ki: NonNegative = 100.0
    filter_order: Annotated[int, Field(ge=1, le=10_000)] = 1


class SpeedControllerConfig(StrictModel):
    """PI gains of the secondary motor's speed loop, Eq. (4.12); the book gives none.

    Attributes:
        kp: proportional gain [V·s/rad].
        ki: integral gain [V/rad].
    """

    kp: NonNegative = 5.0
    ki: NonNegative = 10.0


class PwmConfig(StrictModel):
    """Motor driver: supply V_max and duty register bits N of Eq. (4.15) (0 = ideal driver).

    Attributes:
        bits: duty register bits N of Eq. (4.15); 0: ideal driver (saturation only).
        v_max: supply voltage V_max, the largest |V| the driver gives [V].
    """

    bits: Annotated[int, Field(ge=0, le=16)] = 8
    v_max: Positive = 12.0


class CurrentControlConfig(StrictModel):
    """One closed-loop current-control run of Sect. 4.4.

    Attributes:
        seed: seed of the current sensor's noise.
        rig: "single", the motor alone, or "dual", with the secondary motor on its shaft
            holding the speed.
        preset: the book's motor constants, Table 4.1 or Table 4.2.
        motor: motor constants that override `preset`; None: the preset's.
        dt: control period, at most 0.1 s [s].
        duration: length of the run [s].
        settle: time before the steady-state metrics are taken; rise times are found before
            it [s].
        reference: the current reference and the shaft speed.
        controller: the current PI and its moving-average filter.
        speed_controller: the secondary motor's speed PI (dual rig only).
        pwm: the motor driver.
        sensor: the current sensor (ACS712-5A on the Arduino's ADC).
        encoder: the shaft encoder.
    """

    seed: Seed = 0
    rig: Literal["single", "dual"] = "dual"
    preset: Literal["table4.1", "table4.2"] = "table4.2"
    motor: MotorParams | None = None
    dt: Annotated[float, Field(gt=0, le=0.1, allow_inf_nan=False)] = 1e-3
    duration: Positive = 2.0
    settle: NonNegative = 1.0
    reference: CurrentReference = CurrentReference()
    controller: CurrentControllerConfig = CurrentControllerConfig()
    speed_controller: SpeedControllerConfig = SpeedControllerConfig()
    pwm: PwmConfig = PwmConfig()
    sensor: CurrentSensorParams = CurrentSensorParams()
    encoder: EncoderParams = EncoderParams()

    @model_validator(mode="after")
    def _check_times(self) -> CurrentControlConfig:
        if self.settle >= self.duration:
            raise field_error(
                "settle", f"{self.settle} s must be shorter than duration ({self.duration} s)"
            )
        if self.duration / self.dt > MAX_STEPS:
            raise field_error(
                "duration", f"duration/dt is over {MAX_STEPS} steps; shorten duration or raise dt"
            )
        t = np.arange(self.steps) * self.dt
        if self.steps - int(np.searchsorted(t, self.settle)) < MIN_STEADY_SAMPLES:
            raise field_error(
                "settle",
                f"the steady-state window (duration − settle) holds fewer than "
                f"{MIN_STEADY_SAMPLES} samples; lengthen duration or shorten settle",
            )
        ref = self.reference
        for extreme in (ref.current + ref.amplitude, ref.current - ref.amplitude):
            needed = feedforward_voltage(self.params, extreme, ref.speed)  # Eq. (4.13)
            if abs(needed) > self.pwm.v_max:
                raise field_error(
                    "reference",
                    f"{extreme:g} A at {ref.speed:g} rad/s needs {needed:.3g} V, more "
                    f"than the v_max = {self.pwm.v_max:g} V the driver gives; lower "
                    "reference.current, amplitude or speed",
                )
        if ref.amplitude > 0 and ref.frequency > 0:
            period = 2 * np.pi / ref.frequency
            if self.duration - self.settle < period:
                raise field_error(
                    "duration",
                    f"duration − settle ({self.duration - self.settle:g} s) is shorter than one "
                    f"period of the reference ({period:.4g} s); lengthen duration",
                )
        return self

    @property
    def params(self) -> MotorParams:
        """The motor constants in use."""
        return self.motor if self.motor is not None else PRESETS[self.preset]

    @property
    def steps(self) -> int:
        """Number of control periods simulated."""
        return round(self.duration / self.dt)


def loop_settings(config: CurrentControlConfig) -> LoopSettings:
    """Flatten a config into the numbers the compiled loop takes.

    Args:
        config: the run's config.

    Returns:
        Its gains, sensor, encoder, PWM and control period as plain numbers, with the
            feed-forward voltage of Eq. (4.13) for the reference's current and speed.
    """
    p, c = config.params, config
    return LoopSettings(
        dt=c.dt,
        v_bias=feedforward_voltage(p, c.reference.current, c.reference.speed),
        kp=c.controller.kp,
        ki=c.controller.ki,
        filter_order=c.controller.filter_order,
        dual=c.rig == "dual",
        kp_speed=c.speed_controller.kp,
        ki_speed=c.speed_controller.ki,
        v_max=c.pwm.v_max,
        pwm_bits=c.pwm.bits,
        sensor_ideal=c.sensor.ideal,
        sensitivity=c.sensor.sensitivity,
        zero_voltage=c.sensor.zero_voltage,
        noise_sigma=c.sensor.noise_sigma,
        adc_bits=c.sensor.adc_bits,
        adc_vref=c.sensor.adc_vref,
        encoder_cpr=0 if c.encoder.ideal else c.encoder.counts_per_rev,
        encoder_window=c.encoder.window,
    )


def time_axis(config: CurrentControlConfig) -> np.ndarray:
    """Sample instants [s].

    Args:
        config: the run's config.

    Returns:
        k·dt for every control period k, shape (steps,) [s].
    """
    return np.arange(config.steps) * config.dt


def current_reference(config: CurrentControlConfig) -> np.ndarray:
    """i_ref at every sample [A].

    Args:
        config: the run's config.

    Returns:
        current + amplitude·sin(frequency·t), shape (steps,) [A].
    """
    r = config.reference
    return r.current + r.amplitude * np.sin(r.frequency * time_axis(config))


def metric_window(config: CurrentControlConfig) -> MetricWindow:
    """Steady-state start, rise target and fitting frequency of a config's metrics.

    Args:
        config: the run's config.

    Returns:
        The first sample at or after `settle`; the step target of the rise times [A] (NaN
            for a sinusoid or a step to 0); the sinusoid's frequency [rad/s] (0: none).
    """
    ref = config.reference
    sinusoid = ref.amplitude > 0 and ref.frequency > 0
    return MetricWindow(
        settle_index=int(np.searchsorted(time_axis(config), config.settle)),
        # A step to zero, or a moving reference, has no rise time.
        rise_target=float("nan") if sinusoid or ref.current == 0 else ref.current,
        frequency=ref.frequency if sinusoid else 0.0,
    )


def simulate_batch(
    config: CurrentControlConfig, trials: int, record: bool = True
) -> tuple[dict[str, np.ndarray] | None, dict[str, np.ndarray]]:
    """Run `trials` noise realisations as one batch: (channels or None, per-trial metrics).

    Trial 0 equals the single run of the same config: all draws come from one Generator
    seeded with `config.seed`, row by row. Channels are (trials, steps) arrays.

    Args:
        config: the run's config.
        trials: number of noise realisations.
        record: keep the channels; False saves the memory of long Monte Carlo batches.

    Returns:
        channels: name -> (trials, steps) array: i, i_meas, i_fb [A], omega, omega_meas
            [rad/s], v1 [V], duty1 [counts], v2 [V] and i_ref [A]; None when `record` is
            False.
        metrics: name -> per-trial value, shape (trials,) (metrics_from_sums).
    """
    rng = np.random.default_rng(config.seed)
    steps = config.steps
    noise = (
        np.zeros((trials, steps)) if config.sensor.ideal else rng.standard_normal((trials, steps))
    )
    Ad, Bd = discretize(*rig_matrices(config.params, config.rig == "dual"), config.dt)
    i_ref = current_reference(config)
    window = metric_window(config)
    channels, sums = simulate_loop(
        Ad, Bd, loop_settings(config), window, i_ref, config.reference.speed, noise, record
    )
    if channels is not None:
        channels["i_ref"] = np.broadcast_to(i_ref, noise.shape)
    return channels, metrics_from_sums(config, window, sums)


def metrics_from_sums(
    config: CurrentControlConfig, window: MetricWindow, sums: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """Per-trial metrics from the loop's running sums over the steady-state window.

    steady_state_error and current_rms_error compare the true current with its reference;
    noise_rms is the fed-back signal minus the same filter applied to the true current, so
    the filter's lag on a moving signal is not counted as noise; rise times are 10-90 % of
    the step from rest, found before `settle`; amplitude_ratio and phase_lag [rad, positive
    when lagging] come from a least-squares fit c + a·sin(ωt) + b·cos(ωt) of the current.

    Args:
        config: the run's config.
        window: the window the sums were taken over (metric_window).
        sums: the loop's running sums, name -> shape (trials,) (simulate_loop).

    Returns:
        Name -> per-trial value, shape (trials,): steady_state_error (mean of i − i_ref),
            current_rms_error and noise_rms [A]; speed_mean [rad/s]; saturation_fraction,
            the share of all steps at full voltage; rise_time and rise_time_feedback (of the
            fed-back current) [s], NaN when there is none; amplitude_ratio and phase_lag
            [rad], NaN without a sinusoidal reference.
    """
    t = time_axis(config)[window.settle_index :]
    n = t.size
    m = {
        "steady_state_error": sums["error"] / n,
        "current_rms_error": np.sqrt(sums["error_sq"] / n),
        "noise_rms": np.sqrt(sums["noise_sq"] / n),
        "speed_mean": sums["omega"] / n,
        "saturation_fraction": sums["saturated"] / config.steps,
        "rise_time": sums["t90"] - sums["t10"],
        "rise_time_feedback": sums["t90_fb"] - sums["t10_fb"],
    }
    nan = np.full_like(sums["error"], np.nan)
    if window.frequency > 0:
        basis = np.stack(
            [np.ones_like(t), np.sin(window.frequency * t), np.cos(window.frequency * t)]
        )
        gram = basis @ basis.T
        coef = np.linalg.solve(gram, np.stack([sums["i"], sums["i_sin"], sums["i_cos"]]))
        m["amplitude_ratio"] = np.hypot(coef[1], coef[2]) / config.reference.amplitude
        m["phase_lag"] = -np.arctan2(coef[2], coef[1])
    else:
        m["amplitude_ratio"] = nan
        m["phase_lag"] = nan
    return m


def run_current_control(config: CurrentControlConfig, progress: Progress | None = None) -> Result:
    """Simulate one run and return its metrics and trace.

    Args:
        config: the run's config.
        progress: not used: the run reports no progress.

    Returns:
        The metrics of metrics_from_sums and the trace: t [s] and the channels of
            simulate_batch.
    """
    channels, metrics = simulate_batch(config, trials=1)
    trace = {"t": time_axis(config), **{k: v[0] for k, v in (channels or {}).items()}}
    return Result(metrics={k: float(v[0]) for k, v in metrics.items()}, trace=trace)


CURRENT_CONTROL = Experiment("motor.current", CurrentControlConfig, run_current_control)
