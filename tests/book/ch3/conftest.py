"""Made-up chapter 3 results, so that analysis and report are tested without simulating."""

from __future__ import annotations

import numpy as np
import pytest

from articula.book.ch3.searches import DirectionRow, Directions, Pulse
from articula.book.ch3.study import Ch3Results, DeltaSweep, TimingSweep
from articula.book.ch3.what_ifs import (
    ActuatorModel,
    Mechanism,
    Outcome,
    Release,
    StiffeningRow,
    ValveCase,
)
from articula.control.damping import DampingPolicy
from articula.plants.six_chamber import SixChamberParams

FREE = Outcome(peak_deg=19.0, settling_s=0.9, bend_deg=31.0)


def release(peak: float, rest_s: float) -> Release:
    """A made-up release of the body."""
    return Release(peak, rest_s, 26e3, 0.05, 0.6, (0.5, 0.0), np.array([1.0, 0.0]))


def delta_sweep(peak: list[float | None], settling: list[float | None]) -> DeltaSweep:
    """A made-up Fig. 3.7 sweep over δ = 0, 0.1, ... with open times 0, 5, 10, ... ms."""
    n = len(peak)
    delta = [round(0.1 * i, 1) for i in range(n)]
    return DeltaSweep(delta, peak, settling, [60.0] * n, [0.005 * i for i in range(n)])


def timing_sweep() -> TimingSweep:
    """A made-up 2 × 2 timing grid at δ = 0.3."""
    return TimingSweep(
        0.3,
        np.array([0.0, 0.0, 0.15, 0.15]),
        np.array([0.0, 0.1, 0.0, 0.1]),
        np.array([0.9, 1.0, 0.3, np.nan]),
        np.array([19.0, 25.0, 19.05, 18.0]),
    )


@pytest.fixture
def results() -> Ch3Results:
    """Made-up results in which the book's pulse does not damp and a timed pulse does."""
    p = SixChamberParams()
    model = ActuatorModel(p, 30.0, 0.1, 0.01, 0.03, 0.16, 0.24, FREE)
    timed = Pulse(DampingPolicy(delta=0.2, start=0.13, length=0.08), ("delta", "start", "length"),
                  0.2, 71, 19.0)  # fmt: skip
    own = Pulse(DampingPolicy(delta=0.18, start=0.134, length=0.07),
                ("delta", "start", "length"), 0.19, 71)  # fmt: skip
    rows = (
        DirectionRow(0.0, "none", FREE),
        DirectionRow(0.0, "side 0", Outcome(19.0, 0.2, 31.0)),
        DirectionRow(30.0, "side 0", Outcome(19.7, 0.4, 31.0)),
        DirectionRow(30.0, "own", Outcome(19.7, 0.19, 31.0)),
    )
    return Ch3Results(
        model=model,
        sensitivity=(ValveCase("orifice 0.5 mm", FREE, Outcome(19.5, float("nan"), 31.0)),),
        delta=delta_sweep([18.7, 18.4, 19.9], [0.98, 0.98, None]),
        mechanism=Mechanism(0.1, release(19.0, 0.077), release(18.4, 0.073), 0.68),
        stiffening=(
            StiffeningRow(0.0, (FREE, Outcome(19.0, 0.96, 31.0), Outcome(33.0, 1.1, 31.0))),
        ),
        timing=timing_sweep(),
        book_timing=Pulse(DampingPolicy(delta=0.49), ("delta",), 0.885, 22, 18.97),
        timed=timed,
        directions=Directions(rows, own),
        iterations=12,
        full=False,
    )
