"""Chapter 4's current-control experiment on the dual-motor rig over serial (`articula rig
run`), and the simulated rig `articula emulate motor` puts behind a pseudo-terminal.

The rig closes its loops itself (rigs/motor.py); the host sends the config's gains and
reference, records every control period and takes chapter 4's metrics on the trace: the
same running sums `loops.motor_current` keeps, so an emulated rig gives the in-process
numbers up to float32 on the line. The metrics are taken on the plant's true current where
the rig sends it (an emulated rig); a real rig has only its sensor's (i_meas).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from articula.control.moving_average import moving_average
from articula.control.pwm import pwm_voltage
from articula.errors import ConfigError
from articula.experiments.motor import (
    CurrentControlConfig,
    CurrentReference,
    metric_window,
    metrics_from_sums,
    simulate_batch,
)
from articula.plants.dc_motor import PRESETS
from articula.plants.motor_rig import discretize, rig_matrices
from articula.rigs.link import Link
from articula.rigs.motor import EMULATED, MEASURED, MotorDevice, MotorGains, MotorPins
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import Info, Kind
from articula.rigs.recorder import Recorder
from articula.rigs.run import run_program
from articula.validation import load_experiment_config

DEVICE_CHANNELS = tuple(c.name for c in MEASURED + EMULATED)  # the emulated device's


def channels(info: Info) -> tuple[str, ...]:
    """The recorder's columns: what the rig sends (firmware: the measured channels only).

    Args:
        info: The rig's INFO.

    Returns:
        Its channels' names.
    """
    return tuple(c.name for c in info.channels)


def plant_config(path: Path | None) -> CurrentControlConfig:
    """The motor.current config whose plant an emulated motor rig has.

    Args:
        path: A motor.current config file (its `experiment` key is optional); None: chapter
            4's defaults.

    Returns:
        The config (ConfigError naming the file and key where it does not read).
    """
    return load_experiment_config(path, CurrentControlConfig)


def emulated_motor(config: CurrentControlConfig) -> MotorDevice:
    """A motor rig whose plant is `config`'s (motor, rig, dt, PWM, sensor, encoder); the
    gains, reference, duration and seed are what the host sends.

    Args:
        config: The plant's config (its gains, reference and duration are not used).

    Returns:
        The emulated device, its compiled loop loaded.
    """

    def plant(gains: MotorGains, reference: Program, duration: float, seed: int) -> np.ndarray:
        current, amplitude, frequency, speed = reference.values
        run = config.model_copy(
            update={
                "duration": duration,
                "seed": seed,
                "settle": min(config.settle, duration / 2),
                "controller": config.controller.model_copy(
                    update={"kp": gains.kp, "ki": gains.ki, "filter_order": gains.filter_order}
                ),
                "speed_controller": config.speed_controller.model_copy(
                    update={"kp": gains.kp_speed, "ki": gains.ki_speed}
                ),
                "reference": CurrentReference(
                    current=current, amplitude=amplitude, frequency=frequency, speed=speed
                ),
            }
        )
        channels, _ = simulate_batch(run, trials=1)
        return np.column_stack([channels[name][0] for name in DEVICE_CHANNELS])

    # The loop's compiled code loads (or compiles) now, not while a host waits on a run.
    simulate_batch(config.model_copy(update={"duration": 4 * config.dt, "settle": 0.0}), 1)
    return MotorDevice(plant, config.dt)


# What firmware/src/motor.c is built for: its loop period, H-bridge, sensor and encoder.
FIRMWARE_BUILD = {
    "dt": 0.001,
    "pwm.bits": 8,
    "pwm.v_max": 12.0,
    "sensor.ideal": False,
    "encoder.ideal": False,
    "encoder.counts_per_rev": 375,
    "encoder.window": 50,
}


def firmware_motor(config: CurrentControlConfig) -> MotorPins:
    """The plant behind the motor firmware's pins: `config`'s rig and motor, with the
    loop period, PWM, sensor and encoder the firmware is built for (ConfigError otherwise);
    the firmware computes its feed-forward (4.13) with Table 4.2's R and K.

    Args:
        config: The plant's config.

    Returns:
        The pins' plant for the firmware harness.
    """
    for name, built in FIRMWARE_BUILD.items():
        value = config
        for part in name.split("."):
            value = getattr(value, part)
        if value != built:
            raise ConfigError(
                name,
                f"the motor firmware is built for {built} (got {value}); "
                "change the config or firmware/src/motor.c",
            )
    motor = config.motor or PRESETS[config.preset]
    Ad, Bd = discretize(*rig_matrices(motor, config.rig == "dual"), config.dt)
    if Ad.shape[0] == 3:  # the single rig: no secondary current, V2 acts on nothing
        Ad, Bd = np.pad(Ad, (0, 1)), np.pad(Bd, ((0, 1), (0, 0)))
    return MotorPins(Ad, Bd, config.sensor, config.encoder.counts_per_rev, config.pwm.v_max)


def run_on_rig(config: CurrentControlConfig, link: Link, recorder: Recorder) -> dict[str, float]:
    """One run of `config` on the rig behind `link`.

    Args:
        config: The motor.current config; its gains and reference are sent to the rig.
        link: The line to a motor rig.
        recorder: Takes every sample as it arrives.

    Returns:
        Chapter 4's metrics of the trace (NaN where the rig sends no true current).
    """
    c = config
    gains = MotorGains(
        c.controller.kp,
        c.controller.ki,
        c.controller.filter_order,
        c.speed_controller.kp,
        c.speed_controller.ki,
    )
    r = c.reference
    program = Program(Shape.CURRENT, (r.current, r.amplitude, r.frequency, r.speed))
    link.command(Kind.SET_GAINS, gains.encode())
    link.command(Kind.SET_REFERENCE, program.encode())
    names = [ch.name for ch in link.info.channels]
    t, rows = run_program(link, c.duration, c.seed, recorder.add)
    trace = dict(zip(names, rows.T, strict=True))
    metrics = {k: float(v[0]) for k, v in trace_metrics(c, t, trace).items()}
    if "i" not in trace:  # module docstring: not measurable on the sensor alone
        metrics.update(current_rms_error=math.nan, noise_rms=math.nan)  # null in record.json
    return metrics


def trace_metrics(
    config: CurrentControlConfig, t: np.ndarray, trace: dict[str, np.ndarray]
) -> dict[str, Any]:
    """Chapter 4's metrics (experiments/motor.py) from a recorded trace: the running sums
    of loops.motor_current computed from its columns, then metrics_from_sums.

    Args:
        config: The run's motor.current config.
        t: Sample times [s], shape (n,).
        trace: Column name -> values, shape (n,): i_ref, i_fb, v1 and i (or i_meas), omega
            (or omega_meas).

    Returns:
        The metrics, each an array of one value.
    """
    window = metric_window(config)
    s = window.settle_index
    i = trace.get("i", trace["i_meas"])
    i_ref, fed_back = trace["i_ref"], trace["i_fb"]
    e = i[s:] - i_ref[s:]
    lag_free = fed_back[s:] - moving_average(i, config.controller.filter_order)[s:]
    bits, v_max = config.pwm.bits, config.pwm.v_max
    v_full = v_max if bits == 0 else pwm_voltage((1 << bits) - 1, v_max, bits)
    sums = {
        "error": e.sum(),
        "error_sq": (e * e).sum(),
        "noise_sq": (lag_free**2).sum(),
        "omega": trace.get("omega", trace["omega_meas"])[s:].sum(),
        "saturated": float(np.sum(np.abs(trace["v1"]) >= v_full)),
        "i": i[s:].sum(),
        "i_sin": (i * np.sin(window.frequency * t))[s:].sum(),
        "i_cos": (i * np.cos(window.frequency * t))[s:].sum(),
    }
    for name, y in (("", i), ("_fb", fed_back)):
        for level in (10, 90):
            sums[f"t{level}{name}"] = _first_crossing(t[:s], y[:s], window.rise_target, level)
    return metrics_from_sums(config, window, {k: np.array([v]) for k, v in sums.items()})


def _first_crossing(t: np.ndarray, y: np.ndarray, target: float, percent: int) -> float:
    """When y first reaches `percent` % of target (NaN: never, or no target)."""
    if np.isnan(target):  # no rise to time
        return float("nan")
    reached = np.nonzero(y / target >= percent / 100)[0]
    return float(t[reached[0]]) if reached.size else float("nan")
