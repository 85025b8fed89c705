"""Speed of the chapter-4 closed loop: real-time factor and batch speed-up (issue targets).

    python benchmarks/motor.py [--json]

realtime_factor: simulated seconds per wall second of one 1 kHz closed loop (the Fig. 4.5
config: ACS712 noise, 10-bit ADC, 8-bit PWM, encoder, dual rig), end to end through
`run_current_control` (simulation, metrics, trace). Target >= 1000.
batch_speedup: wall time of 1,000 seeds run as 1,000 separate `run_current_control` calls
divided by the same 1,000 seeds run as one batch (`simulate_batch(record=False)`: the
same metrics from running sums, no stored trace), for 1 s runs; the table also shows it for
other run lengths, since a separate run pays a fixed cost that the batch shares.
Target >= 20. The interpreted loop (numba's pure-Python original of the same kernel) is timed
in the same process as the baseline for the compiled one.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from common import run

from articula.experiments.motor import (
    CurrentControlConfig,
    current_reference,
    loop_settings,
    metric_window,
    run_current_control,
    simulate_batch,
    time_axis,
)
from articula.loops.motor_current import CHANNELS, SUMS, _loop
from articula.plants.motor_rig import discretize, rig_matrices

TRIALS = 1000
DURATIONS = (0.1, 0.3, 1.0, 3.0)  # [s] simulated per run; batch_speedup is reported at 1 s


def _median_time(fn, repeats: int) -> float:
    fn()  # warm-up: numba compilation or cache load
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _interpreted_seconds(config: CurrentControlConfig) -> float:
    """Wall time of the same loop body run by the Python interpreter (numba's py_func)."""
    s = loop_settings(config)
    window = metric_window(config)
    Ad, Bd = discretize(*rig_matrices(config.params, True), config.dt)
    noise = np.random.default_rng(0).standard_normal((config.steps, 1))
    out = np.empty((len(CHANNELS), config.steps, 1))
    sums = np.zeros((len(SUMS), 1))
    t = time_axis(config)
    start = time.perf_counter()
    _loop.py_func(
        Ad, Bd, current_reference(config), config.reference.speed, noise, out, sums, True,
        window.settle_index, window.rise_target, np.sin(0 * t), np.cos(0 * t),
        s.dt, s.v_bias, s.kp, s.ki, s.filter_order, s.dual, s.kp_speed, s.ki_speed,
        s.v_max, s.pwm_bits, s.sensor_ideal, s.sensitivity, s.zero_voltage, s.noise_sigma,
        s.adc_bits, s.adc_vref, s.encoder_cpr, s.encoder_window,
    )  # fmt: skip
    return time.perf_counter() - start


def _batch_speedup(duration: float) -> tuple[float, float, float]:
    """(separate [s], batch [s], ratio) for TRIALS seeds of a run of `duration` [s]."""
    config = CurrentControlConfig(duration=duration, settle=duration / 2)

    def separate() -> None:
        for seed in range(TRIALS):
            run_current_control(config.model_copy(update={"seed": seed}))

    def batch() -> None:
        simulate_batch(config, TRIALS, record=False)

    t_separate = _median_time(separate, repeats=3)
    t_batch = _median_time(batch, repeats=3)
    return t_separate, t_batch, t_separate / t_batch


def measure() -> dict[str, object]:
    """Run every timing and return the figures."""
    long_run = CurrentControlConfig(duration=20.0, settle=1.0)
    single = _median_time(lambda: run_current_control(long_run), repeats=5)
    kernel_only = _median_time(lambda: simulate_batch(long_run, 1), repeats=5)
    short = CurrentControlConfig(duration=1.0, settle=0.5)
    interpreted = _interpreted_seconds(short)
    by_duration = {d: _batch_speedup(d) for d in DURATIONS}
    rng = np.random.default_rng(0)
    noise = _median_time(lambda: rng.standard_normal((TRIALS, short.steps)), repeats=5)
    t_separate, t_batch, speedup = by_duration[1.0]
    return {
        "realtime_factor": long_run.duration / single,
        "kernel_realtime_factor": long_run.duration / kernel_only,
        "interpreted_realtime_factor": short.duration / interpreted,
        "separate_runs_s": t_separate,
        "batch_s": t_batch,
        "batch_speedup": speedup,
        "batch_noise_draw_s": noise,
        "batch_speedup_by_duration": {str(d): r for d, (_, _, r) in by_duration.items()},
    }


def table(m: dict) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        ["realtime_factor (run_current_control, 20 s)", f"{m['realtime_factor']:.0f}", ">= 1000"],
        ["  compiled kernel only", f"{m['kernel_realtime_factor']:.0f}", ""],
        ["  baseline: same loop interpreted", f"{m['interpreted_realtime_factor']:.1f}", ""],
        [f"{TRIALS} separate 1 s runs [s]", f"{m['separate_runs_s']:.3f}", ""],
        [f"one batch of {TRIALS} × 1 s [s]", f"{m['batch_s']:.3f}", ""],
        ["  of which drawing the sensor noise [s]", f"{m['batch_noise_draw_s']:.3f}", ""],
        ["batch_speedup (1 s runs)", f"{m['batch_speedup']:.1f}", ">= 20"],
    ]
    rows += [[f"  batch speed-up, {d} s runs", f"{r:.1f}", ""]
             for d, r in m["batch_speedup_by_duration"].items()]  # fmt: skip
    title = "chapter-4 current loop (1 kHz, dual rig, noisy sensor, 8-bit PWM)"
    return title, ["measure", "value", "target"], rows


if __name__ == "__main__":
    run(__doc__, measure, table)
