"""Made-up chapter-2 results: every object the study returns, built without simulating."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from articula.book.ch2.book_values import CONTROLLERS, FREQUENCIES
from articula.book.ch2.study import (
    KD_PROBE,
    Ch2Results,
    Comparison,
    Tuning,
    ZieglerNichols,
)
from articula.book.ch2.tuning import SEQUENCE, KdProbe, TuningConfig, TuningRun
from articula.tuning.coordinate_descent import DescentResult, DescentStep
from articula.tuning.manual import ManualResult, Trial, ziegler_nichols
from articula.tuning.response import Response, step_features

GROW = 10.0 + 5.0 * np.arange(len(FREQUENCIES))  # made-up medians [°] rising with frequency


def _table_of(medians: dict[str, np.ndarray]) -> dict[str, dict[float, tuple[float, float, float]]]:
    """A made-up Table 2.3: name -> medians per frequency, quartiles ±1."""
    return {n: {f: (float(m), float(m) - 1, float(m) + 1)
                for f, m in zip(FREQUENCIES, medians[n], strict=True)}
            for n in CONTROLLERS}  # fmt: skip


def _sinusoid_trace(f: float, ratio: float, lag: float) -> dict[str, np.ndarray]:
    """A trace whose sensor reading follows 45 − 45·cos(2πft) with this ratio and lag [rad]."""
    t = np.arange(0, 10, 1 / 30)
    w = 2 * np.pi * f
    return {"t": t, "theta_ref_deg": 45 - 45 * np.cos(w * t),
            "theta_meas_deg": 45 - 45 * ratio * np.cos(w * t - lag)}  # fmt: skip


def _manual(kp: float, ki: float, experiments: int, within: bool) -> ManualResult:
    t = np.linspace(0, 1, 10)
    r = Response(t, np.ones_like(t), np.ones_like(t))
    f = step_features(r, 0.1)
    kd = [0.0] * (experiments - 1) + [0.01]
    trials = [Trial(np.array([kp, ki, k]), r, f, "made up") for k in kd]
    return ManualResult(np.array([kp, ki, 0.0]), trials, within)


def _descent(levels: tuple[float, ...], k: list[float], evaluations: int) -> TuningRun:
    start = DescentStep(0, np.array([1.0, 1.0, 0.1]), np.array([0.5, 0.5, 0.05]), 30.0, 1)
    end = DescentStep(1, np.array(k), np.array([0.1, 0.1, 0.01]), 20.0, evaluations)
    return TuningRun(levels, DescentResult(end.k, 20.0, evaluations, [start, end]))


def _probe(shift: float) -> KdProbe:
    """K_d = 0 best by far: M rises by `shift` per rung."""
    noise = np.array([0.3, -0.2, 0.1, -0.4])
    cost = np.array([20.0 + shift * j + noise for j in range(len(KD_PROBE))])
    return KdProbe(KD_PROBE, cost, np.zeros_like(cost), np.zeros(cost.shape, dtype=bool))


@pytest.fixture
def table_of() -> Callable[[dict[str, np.ndarray]], dict[str, dict[float, tuple]]]:
    """table_of(medians by controller) -> a made-up Table 2.3 with quartiles ±1."""
    return _table_of


@pytest.fixture
def sinusoid_trace() -> Callable[[float, float, float], dict[str, np.ndarray]]:
    """sinusoid_trace(f [Hz], ratio, lag [rad]) -> a made-up trial-0 trace."""
    return _sinusoid_trace


@pytest.fixture
def made_up() -> Callable[..., Ch2Results]:
    """made_up(table=None, missed=False) -> Ch2Results: tuned gains, two probed gain sets and
    a Table 2.3 (default: medians rising with frequency, automatic and scheduled better)."""

    def build(table=None, missed: bool = False) -> Ch2Results:
        manual = {
            "90": _manual(1.27, 2.56, 15, True),
            "15": _manual(1.9, 0.76, 13, not missed),
            "45": _manual(1.27, 1.14, 13, True),
            "75": _manual(1.27, 1.71, 14, True),
        }
        auto = {"sequence": _descent(SEQUENCE, [0.87, 5.44, 0.04], 64),
                "15": _descent((15.0,), [0.64, 1.21, 0.165], 70),
                "45": _descent((45.0,), [0.46, 2.98, 0.09], 66),
                "75": _descent((75.0,), [0.91, 5.08, 0.1], 64)}  # fmt: skip
        zn = ZieglerNichols(7.11, 0.392, ziegler_nichols(7.11, 0.392, "PI"),
                            ziegler_nichols(7.11, 0.392, "PID"))  # fmt: skip
        offset = {"ordinary-manual": 6, "piecewise-manual": 4, "fuzzy-manual": 4,
                  "ordinary-auto": 3, "piecewise-auto": 1, "fuzzy-auto": 1}  # fmt: skip
        table = table or _table_of({n: GROW + offset[n] for n in CONTROLLERS})
        calibration = {f: _sinusoid_trace(f, 0.5, 0.3) for f in (0.05, 5.0)}
        comparison = Comparison(table, {}, calibration, 10, 45.0, 45.0, 0.05)
        probes = {"automatic sequence": _probe(1.0), "manual 90": _probe(2.0)}
        return Ch2Results(Tuning(TuningConfig(), manual, auto, zn), probes, comparison)

    return build
