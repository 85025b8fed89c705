"""Chapter 3's study: the packaged sweeps through the runner, the extra runs, the figures."""

from __future__ import annotations

import shutil
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from articula.book.ch3 import searches, what_ifs
from articula.book.ch3.book_values import BOOK
from articula.book.study import Study, packaged, read_trace
from articula.book.text import finite_or_none
from articula.plants.six_chamber import SixChamberParams
from articula.plants.six_chamber_sim import fill_time
from articula.runs.sweep import expand_sweep
from articula.validation import load_toml

DELTA, TIMING = "delta_sweep", "timing_sweep"  # sweep folders; their files are copied beside
SEARCH_STEPS = 3  # progress steps after the sweeps: two searches and the any-direction search
ITERATIONS = {"quick": 12, "full": 40}  # coordinate-descent sweeps at most


@dataclass(frozen=True)
class DeltaSweep:
    """Fig. 3.7: the sensor's response against δ (None where a value is not finite).

    Attributes:
        delta: damping actuation ratios δ of Eq. (3.4), as swept.
        peak_deg: peak past rest [deg].
        settling_s: settling time to the band [s].
        overshoot_pct: swing past rest over the bend at the vent command [%].
        open_s: the pulse's valve open time for each δ [s].
    """

    delta: list[float]
    peak_deg: list[float | None]
    settling_s: list[float | None]
    overshoot_pct: list[float | None]
    open_s: list[float]


@dataclass(frozen=True)
class TimingSweep:
    """Settling [s] (NaN: never) and peak [deg] (true angle) per pulse start and length [s]."""

    delta: float
    start: np.ndarray
    length: np.ndarray
    settling_s: np.ndarray
    peak_deg: np.ndarray


@dataclass(frozen=True)
class Ch3Results:
    """Everything chapter 3's report shows."""

    model: what_ifs.ActuatorModel
    sensitivity: tuple[what_ifs.ValveCase, ...]
    delta: DeltaSweep
    mechanism: what_ifs.Mechanism
    stiffening: tuple[what_ifs.StiffeningRow, ...]
    timing: TimingSweep
    book_timing: searches.Pulse
    timed: searches.Pulse
    directions: searches.Directions
    iterations: int
    full: bool


def sweep_configs(study: Study, name: str) -> list[dict[str, Any]]:
    """The configs of packaged sweep `name` ("delta" or "timing") at the study's size; the
    file is copied to OUT/<name>_sweep.toml."""
    path = packaged("ch3", f"{name}_{study.size}.toml")
    study.out.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(path, study.out / f"{name}_sweep.toml")
    return expand_sweep(load_toml(path))


def run_study(study: Study) -> Ch3Results:
    """Run the sweeps (resuming finished runs), the what-ifs and the searches; draw the figures."""
    delta_configs, timing_configs = sweep_configs(study, "delta"), sweep_configs(study, "timing")
    sweeps = len(delta_configs) + len(timing_configs)
    total = sweeps + SEARCH_STEPS
    delta = _delta(study, delta_configs, total)
    timing = _timing(study, timing_configs, len(delta_configs), total)
    model, sensitivity = what_ifs.actuator_model(), what_ifs.sensitivity()
    mechanism = what_ifs.mechanism(delta.delta, delta.peak_deg)
    stiffening = what_ifs.stiffening()
    iterations = ITERATIONS[study.size]
    book_timing = searches.book_timing(iterations)
    study.progress(sweeps + 1, total)
    timed = searches.timed(iterations)
    study.progress(sweeps + 2, total)
    directions = searches.directions(timed.policy, iterations)
    _search_figure(study.out, book_timing, timed)
    study.progress(total, total)
    return Ch3Results(
        model,
        sensitivity,
        delta,
        mechanism,
        stiffening,
        timing,
        book_timing,
        timed,
        directions,
        iterations,
        study.full,
    )


def _delta(study: Study, configs: Sequence[Mapping[str, Any]], total: int) -> DeltaSweep:
    """Run the δ sweep and draw Fig. 3.7."""
    from articula.book.ch3.figures import delta_study

    table = study.sweep(configs, DELTA, 0, total).to_pydict()
    p = SixChamberParams()
    delta = [float(d) for d in table["damping.delta"]]
    result = DeltaSweep(
        delta,
        [finite_or_none(x) for x in table["peak_deg"]],
        [finite_or_none(x) for x in table["settling_s"]],
        [finite_or_none(x) for x in table["overshoot_pct"]],
        [fill_time(p, d * p.supply) for d in delta],
    )
    curves = {}
    for config in configs:
        trace = read_trace(study.out / DELTA, config)
        after = trace["t"] >= config["hold"]
        curves[config["damping"]["delta"]] = (
            trace["t"][after] - config["hold"],
            np.degrees(trace["bend_sensor"][after]),
        )
    delta_study(curves, delta, result.peak_deg, result.settling_s, BOOK, study.out / "fig3_7.png")
    return result


def _timing(
    study: Study, configs: Sequence[Mapping[str, Any]], done: int, total: int
) -> TimingSweep:
    """Run the pulse-timing grid and draw its map."""
    from articula.book.ch3.figures import timing_map

    table = study.sweep(configs, TIMING, done, total).to_pydict()
    result = TimingSweep(
        float(configs[0]["damping"]["delta"]),
        np.array(table["damping.start"], dtype=float),
        np.array(table["damping.length"], dtype=float),
        np.array([np.nan if s is None else s for s in table["settling_s"]], dtype=float),
        np.array(table["peak_deg"], dtype=float),
    )
    starts, lengths = np.unique(result.start), np.unique(result.length)
    grid = np.full((lengths.size, starts.size), np.nan)
    for s, h, v in zip(result.start, result.length, result.settling_s, strict=True):
        grid[np.searchsorted(lengths, h), np.searchsorted(starts, s)] = v
    timing_map(starts, lengths, grid, result.delta, study.out / "timing.png")
    return result


def _search_figure(out: Path, book_timing: searches.Pulse, timed: searches.Pulse) -> None:
    """The best pulses found against none and the book's."""
    from articula.book.ch3.figures import best_pulse

    curves, pressures = searches.pulse_curves(searches.compared(book_timing, timed))
    best_pulse(curves, pressures, out / "search.png")
