"""Chapter 4 experiment: PI + feed-forward current control on the single or dual motor rig."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from articula.control.current_loop import LoopSettings, simulate_loop
from articula.control.moving_average import moving_average
from articula.experiments.registry import Result, register
from articula.metrics import rise_time, sinusoid_fit
from articula.plants.dc_motor import PRESETS, MotorParams, feedforward_voltage
from articula.plants.motor_rig import discretize, rig_matrices
from articula.plants.motor_sensors import CurrentSensorParams, EncoderParams

Finite = Annotated[float, Field(allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
MAX_STEPS = 10_000_000


class _Strict(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class ReferenceConfig(_Strict):
    """Current reference i_ref(t) = current + amplitude·sin(frequency·t) and the shaft speed."""

    current: Finite = 1.0  # i_ss [A]
    speed: Finite = 5.0  # ω_ss [rad/s], held by the secondary on the dual rig
    amplitude: NonNegative = 0.0  # [A]
    frequency: NonNegative = 0.0  # [rad/s]


class CurrentControllerConfig(_Strict):
    """PI gains of Eq. (4.14) and the moving-average order of Eq. (4.17) (1 = unfiltered)."""

    kp: NonNegative = 10.0  # [V/A]
    ki: NonNegative = 100.0  # [V/(A·s)]
    filter_order: Annotated[int, Field(ge=1, le=10_000)] = 1


class SpeedControllerConfig(_Strict):
    """PI gains of the secondary motor's speed loop, Eq. (4.12); the book gives none."""

    kp: NonNegative = 5.0  # [V·s/rad]
    ki: NonNegative = 10.0  # [V/rad]


class PwmConfig(_Strict):
    """Motor driver: supply V_max and duty register bits N of Eq. (4.15) (0 = ideal driver)."""

    bits: Annotated[int, Field(ge=0, le=16)] = 8
    v_max: Positive = 12.0  # [V]


class CurrentControlConfig(_Strict):
    """One closed-loop current-control run of Sect. 4.4."""

    seed: Annotated[int, Field(ge=0)] = 0
    rig: Literal["single", "dual"] = "dual"
    preset: Literal["table4.1", "table4.2"] = "table4.2"
    motor: MotorParams | None = None  # overrides `preset` when given
    dt: Annotated[float, Field(gt=0, le=0.1, allow_inf_nan=False)] = 1e-3  # [s]
    duration: Positive = 2.0  # [s]
    settle: NonNegative = 1.0  # [s] before steady-state metrics are taken
    reference: ReferenceConfig = ReferenceConfig()
    controller: CurrentControllerConfig = CurrentControllerConfig()
    speed_controller: SpeedControllerConfig = SpeedControllerConfig()
    pwm: PwmConfig = PwmConfig()
    sensor: CurrentSensorParams = CurrentSensorParams()
    encoder: EncoderParams = EncoderParams(window=50)

    @model_validator(mode="after")
    def _check_times(self) -> CurrentControlConfig:
        if self.settle >= self.duration:
            raise ValueError(
                f"settle ({self.settle} s) must be shorter than duration ({self.duration} s)"
            )
        if self.duration / self.dt > MAX_STEPS:
            raise ValueError(f"duration/dt is over {MAX_STEPS} steps; shorten duration or raise dt")
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
    """Flatten a config into the numbers the compiled loop takes."""
    p, c = config.params, config
    return LoopSettings(
        dt=c.dt, v_bias=feedforward_voltage(p, c.reference.current, c.reference.speed),
        kp=c.controller.kp, ki=c.controller.ki,
        filter_order=c.controller.filter_order, dual=c.rig == "dual",
        kp_speed=c.speed_controller.kp, ki_speed=c.speed_controller.ki,
        v_max=c.pwm.v_max, pwm_bits=c.pwm.bits, sensor_ideal=c.sensor.ideal,
        sensitivity=c.sensor.sensitivity, zero_voltage=c.sensor.zero_voltage,
        noise_sigma=c.sensor.noise_sigma, adc_bits=c.sensor.adc_bits,
        adc_vref=c.sensor.adc_vref, encoder_cpr=0 if c.encoder.ideal else c.encoder.counts_per_rev,
        encoder_window=c.encoder.window,
    )  # fmt: skip


def time_axis(config: CurrentControlConfig) -> np.ndarray:
    """Sample instants [s]."""
    return np.arange(config.steps) * config.dt


def current_reference(config: CurrentControlConfig) -> np.ndarray:
    """i_ref at every sample [A]."""
    r = config.reference
    return r.current + r.amplitude * np.sin(r.frequency * time_axis(config))


def simulate_batch(config: CurrentControlConfig, trials: int) -> dict[str, np.ndarray]:
    """Run `trials` noise realisations as one batch; channels are (trials, steps) arrays.

    Trial 0 equals the single run of the same config: all draws come from one Generator
    seeded with `config.seed`, row by row.
    """
    rng = np.random.default_rng(config.seed)
    steps = config.steps
    noise = (
        np.zeros((trials, steps)) if config.sensor.ideal else rng.standard_normal((trials, steps))
    )
    Ad, Bd = discretize(*rig_matrices(config.params, config.rig == "dual"), config.dt)
    i_ref = current_reference(config)
    channels = simulate_loop(Ad, Bd, loop_settings(config), i_ref, config.reference.speed, noise)
    channels["i_ref"] = np.broadcast_to(i_ref, noise.shape)
    return channels


def batch_metrics(config: CurrentControlConfig, ch: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Per-trial metrics of a batch: rise time, steady-state error, noise, sinusoid tracking."""
    t = time_axis(config)
    steady = t >= config.settle
    i, i_ref, i_fb = ch["i"][:, steady], ch["i_ref"][:, steady], ch["i_fb"][:, steady]
    i_true_filtered = moving_average(ch["i"], config.controller.filter_order)[:, steady]
    ref = config.reference
    full = (1 << config.pwm.bits) - 1
    saturated = (
        np.abs(ch["duty1"]) >= full if config.pwm.bits else np.abs(ch["v1"]) >= config.pwm.v_max
    )
    m: dict[str, np.ndarray] = {
        "steady_state_error": (i - i_ref).mean(axis=1),
        "current_rms_error": np.sqrt(((i - i_ref) ** 2).mean(axis=1)),
        # Noise left in the fed-back signal: the filtered measurement minus the same filter
        # applied to the true current, so the filter's lag on a moving signal is not counted.
        "noise_rms": np.sqrt(((i_fb - i_true_filtered) ** 2).mean(axis=1)),
        "speed_mean": ch["omega"][:, steady].mean(axis=1),
        "saturation_fraction": saturated.mean(axis=1),
    }
    nan = np.full(i.shape[0], np.nan)
    if ref.amplitude > 0 and ref.frequency > 0:
        amplitude, phase = sinusoid_fit(t[steady], i, ref.frequency)
        m["amplitude_ratio"] = amplitude / ref.amplitude
        m["phase_lag"] = -phase  # [rad], positive when the current lags the reference
        m["rise_time"] = nan
        m["rise_time_feedback"] = nan
    else:
        m["amplitude_ratio"] = nan
        m["phase_lag"] = nan
        m["rise_time"] = rise_time(t, ch["i"], start=0.0, target=ref.current)
        m["rise_time_feedback"] = rise_time(t, ch["i_fb"], start=0.0, target=ref.current)
    return m


@register("motor.current", CurrentControlConfig)
def run_current_control(config: CurrentControlConfig) -> Result:
    """Simulate one run and return its metrics and trace."""
    ch = simulate_batch(config, trials=1)
    metrics = {k: float(v[0]) for k, v in batch_metrics(config, ch).items()}
    trace = {"t": time_axis(config), **{k: v[0] for k, v in ch.items()}}
    return Result(metrics=metrics, trace=trace)
