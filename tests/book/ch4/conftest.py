"""Made-up chapter 4 results, so that analysis and report are tested without simulating."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.book.ch4.analysis import BandwidthRow
from articula.book.ch4.study import Ch4Results, ModelNumbers

NAN = math.nan
GAINS = {"kp": 10.0, "ki": 100.0, "R": 8.35, "dt": 1e-3}


def metrics(**values: float) -> dict[str, float]:
    """One figure run's metrics: NaN for every metric not given, k = 1 unless given."""
    names = ("steady_state_error", "current_rms_error", "noise_rms", "speed_mean",
             "saturation_fraction", "rise_time", "rise_time_feedback", "amplitude_ratio",
             "phase_lag")  # fmt: skip
    return {**{n: NAN for n in names}, "k": 1, **values}


def figure_runs(**changes: dict[str, float]) -> dict[str, dict[str, float]]:
    """Figure runs close to ours in quick mode, with some metrics changed per run."""
    runs = {
        "fig4_5": metrics(rise_time=0.001, rise_time_feedback=0.001, noise_rms=0.020),
        "fig4_6": metrics(amplitude_ratio=0.819, phase_lag=0.27, noise_rms=0.020),
        "fig4_7": metrics(amplitude_ratio=0.574, phase_lag=0.18, noise_rms=0.020),
        "fig4_8": metrics(rise_time=0.001, rise_time_feedback=0.028, noise_rms=0.003, k=50),
        "fig4_9": metrics(amplitude_ratio=0.841, phase_lag=0.18, noise_rms=0.003, k=50),
    }
    return {name: {**m, **changes.get(name, {})} for name, m in runs.items()}


def row(k: int, measured: float, noise: float, saturation: float = 0.0) -> BandwidthRow:
    """A made-up bandwidth row swept at 2, 4 and 8 rad/s."""
    return BandwidthRow(
        k=k, frequencies=np.array([2.0, 4.0, 8.0]), ratios=np.array([1.0, 0.9, 0.6]),
        measured=measured, predicted=measured, stable=True, noise=noise, low_frequency=2.0,
        error_low=0.01, saturation=saturation,
    )  # fmt: skip


MODEL = ModelNumbers(
    omega_per_volt=2.5469, current_per_volt=0.011479, omega_at_supply=30.563,
    current_at_supply=0.13775, simulated_omega=30.563, simulated_current=0.13775,
    current_with_load=0.9018, denominator=0.139385, omega_c=8.138239, stall_current=1.437,
    no_load_speed=26.76,
)  # fmt: skip
ROWS = [row(1, 8.39, 0.0206, 0.07), row(4, 8.59, 0.0102), row(256, math.inf, 0.0014, 0.37)]


@pytest.fixture
def results() -> Ch4Results:
    """Results shaped like a quick run's."""
    return Ch4Results(MODEL, figure_runs(), GAINS, ROWS, sweep_runs=15)
