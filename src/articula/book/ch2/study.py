"""Chapter 2's study: the tuning runs (Table 2.2), the K_d probe and the Table 2.3 sweep."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from articula.book.ch2.book_values import (
    BOOK_TABLE_2_3,
    CONTROLLERS,
    FIG_2_5,
    FIG_2_6,
    FREQUENCIES,
    SINUSOID_FIGURES,
)
from articula.book.ch2.tuning import (
    SEQUENCE,
    SUBRANGES,
    KdProbe,
    TuningConfig,
    TuningRun,
    auto_run,
    kd_probe,
    manual_run,
    step_reference,
)
from articula.book.study import Study, packaged, read_metrics, read_trace
from articula.loops.pneunet_pid import SimulatedRig
from articula.runs.records import atomic_write
from articula.runs.sweep import expand_sweep
from articula.tuning.manual import Ladder, ManualResult, ultimate_gain, ziegler_nichols
from articula.validation import load_toml, parse_model

Row = tuple[float, float, float]  # median, Q1, Q3 of E (2.7) over the trials [°]
Trace = dict[str, np.ndarray]
# [°] the top of the range: the manual procedure's step of Fig. 2.5 (whose gains ordinary PID
# uses) and the Ziegler-Nichols ultimate-gain search; its key among the manual runs.
FULL_LEVEL = 90.0
FULL_KEY = f"{FULL_LEVEL:g}"
MANUAL_LEVELS = (FULL_LEVEL, *SUBRANGES)  # [°] steps of the manual procedure (Table 2.2)
ZN_LADDER = Ladder(
    start=0.25, factor=1.25, stop=200.0
)  # P-only K_p rungs [counts/°] for the ultimate gain
ZN_SEED_OFFSET = 90_000  # its rig's noise seed: the manual seed plus this
KD_PROBE = (0.0, 0.02, 0.05, 0.1, 0.2)  # [counts·s/°] K_d values tried on each tuned gain set
KD_PROBE_SEEDS = 16
TUNING_STEPS = len(MANUAL_LEVELS) + 1 + len(SUBRANGES) + 1  # manual, automatic, Ziegler-Nichols
CALIBRATED = "fuzzy-auto"  # the controller whose trial 0 is fitted at every frequency
SWEEP = "table2_3_sweep"  # the sweep folder; its file (with the tuned gains) is SWEEP.toml


@dataclass(frozen=True, eq=False)
class ZieglerNichols:
    """Ultimate gain K_u [counts/°] and period T_u [s] at 90°, and the classic PI and PID rows."""

    ku: float
    tu: float
    pi: np.ndarray
    pid: np.ndarray


@dataclass(frozen=True)
class Tuning:
    """The tuning runs: manual by level ("90", "15", ...), automatic by key ("sequence", "15",
    ...), Ziegler-Nichols at 90°, and the config they ran with."""

    config: TuningConfig
    manual: dict[str, ManualResult]
    auto: dict[str, TuningRun]
    zn: ZieglerNichols


@dataclass(frozen=True)
class Comparison:
    """The Table 2.3 sweep: controller -> frequency [Hz] -> (median, Q1, Q3) of E [°]; trial 0
    of every controller at the figures' frequencies (`traces`) and of CALIBRATED at every
    frequency (`calibration`); the trials per cell, the reference's offset and amplitude [°]
    and the actuators' spread (fraction, one σ)."""

    table: dict[str, dict[float, Row]]
    traces: dict[float, dict[str, Trace]]
    calibration: dict[float, Trace]
    trials: int
    offset_deg: float
    amplitude_deg: float
    trial_spread: float


@dataclass(frozen=True)
class Ch2Results:
    """Everything chapter 2 ran: tuning, K_d probes by gain set, the comparison."""

    tuning: Tuning
    probes: dict[str, KdProbe]
    comparison: Comparison


def run_study(study: Study) -> Ch2Results:
    """Tune, probe K_d, run the Table 2.3 sweep into OUT/table2_3_sweep, draw Figs. 2.5-2.10."""
    study.out.mkdir(parents=True, exist_ok=True)
    total = TUNING_STEPS + len(FREQUENCIES) * len(CONTROLLERS)
    config = parse_model(TuningConfig, load_toml(packaged("ch2", f"tuning_{study.size}.toml")))
    tuning = tune(config, lambda done: study.progress(done, total))
    _tuning_figures(tuning, study.out)
    probes = probe_kd(tuning)
    comparison = compare(study, controllers(tuning), TUNING_STEPS)
    _comparison_figures(comparison, study.out)
    return Ch2Results(tuning, probes, comparison)


def tune(config: TuningConfig, progress: Callable[[int], None]) -> Tuning:
    """The manual procedure at every level, coordinate descent on the whole-range sequence
    and on each subrange, and Ziegler-Nichols; progress gets the steps done."""
    done = 0
    manual = {}
    for level in MANUAL_LEVELS:
        manual[f"{level:g}"] = manual_run(config, level)
        done += 1
        progress(done)
    auto = {}
    runs = [("sequence", SEQUENCE), *[(f"{level:g}", (level,)) for level in SUBRANGES]]
    for index, (name, levels) in enumerate(runs):
        auto[name] = auto_run(config, levels, index)
        done += 1
        progress(done)
    zn = ziegler_nichols_at_90(config)
    progress(done + 1)
    return Tuning(config, manual, auto, zn)


def ziegler_nichols_at_90(config: TuningConfig) -> ZieglerNichols:
    """Ultimate gain at 90° and the classic table, for comparison with the procedure."""
    reference = step_reference((FULL_LEVEL,), config.manual.hold, config.plant.pwm_period)
    rig = SimulatedRig(config.plant, reference, config.manual.seed + ZN_SEED_OFFSET)
    ku, tu, _ = ultimate_gain(rig, ZN_LADDER, config.manual.band)
    return ZieglerNichols(ku, tu, ziegler_nichols(ku, tu, "PI"), ziegler_nichols(ku, tu, "PID"))


def probe_kd(tuning: Tuning) -> dict[str, KdProbe]:
    """Every tuned gain set ("automatic KEY", "manual KEY") with its K_d set to each KD_PROBE."""
    c = tuning.config
    sets = {
        f"automatic {k}": (r.result.k, r.levels, c.auto.hold) for k, r in tuning.auto.items()
    } | {f"manual {k}": (r.gains, (float(k),), c.manual.hold) for k, r in tuning.manual.items()}
    return {
        name: kd_probe(c.plant, gains, levels, hold, KD_PROBE, KD_PROBE_SEEDS, c.manual.band)
        for name, (gains, levels, hold) in sets.items()
    }


def controllers(tuning: Tuning) -> dict[str, dict[str, Any]]:
    """[controller] tables of the six compared controllers, from the tuned gains: ordinary PID
    with the 90° manual or whole-range automatic gains, scheduled ones with the subranges'."""

    def row(k: np.ndarray) -> list[float]:
        return [round(float(g), 6) for g in k]

    single = {
        "manual": [row(tuning.manual[FULL_KEY].gains)],
        "auto": [row(tuning.auto["sequence"].result.k)],
    }
    scheduled = {
        "manual": [row(tuning.manual[f"{p:g}"].gains) for p in SUBRANGES],
        "auto": [row(tuning.auto[f"{p:g}"].result.k) for p in SUBRANGES],
    }
    tables = {}
    for name in CONTROLLERS:
        kind, method = name.split("-")
        if kind == "ordinary":
            tables[name] = {"name": name, "schedule": "constant", "gains": single[method]}
        else:
            tables[name] = {
                "name": name,
                "schedule": kind,
                "gains": scheduled[method],
                "points_deg": list(SUBRANGES),
            }
    return tables


def compare(study: Study, tables: Mapping[str, dict[str, Any]], done: int) -> Comparison:
    """Run the packaged Table 2.3 sweep with a [grid] of the controllers; the sweep file goes
    to OUT/table2_3_sweep.toml. Progress counts on from `done`."""
    spec = load_toml(packaged("ch2", f"table2_3_{study.size}.toml"))
    spec = {**spec, "grid": {"controller": [tables[n] for n in CONTROLLERS]}}
    atomic_write(study.out / f"{SWEEP}.toml", tomli_w.dumps(spec).encode())
    configs = expand_sweep(spec)
    study.sweep(configs, SWEEP, done=done)
    folder = study.out / SWEEP
    table: dict[str, dict[float, Row]] = {n: {} for n in CONTROLLERS}
    traces: dict[float, dict[str, Trace]] = {f: {} for f in SINUSOID_FIGURES}
    calibration: dict[float, Trace] = {}
    for cfg in configs:
        name, f = cfg["controller"]["name"], float(cfg["reference"]["frequency"])
        m = read_metrics(folder, cfg)
        table[name][f] = (m["error_median_deg"], m["error_q1_deg"], m["error_q3_deg"])
        if f in SINUSOID_FIGURES or name == CALIBRATED:
            trace = read_trace(folder, cfg)
            if f in SINUSOID_FIGURES:
                traces[f][name] = trace
            if name == CALIBRATED:
                calibration[f] = trace
    first = configs[0]
    return Comparison(
        table,
        traces,
        calibration,
        first["trials"],
        first["reference"]["offset_deg"],
        first["reference"]["amplitude_deg"],
        float(first["plant"]["trial_spread"]),
    )


def _tuning_figures(tuning: Tuning, out: Path) -> None:
    """Fig. 2.5 (the manual steps to 90°) and Fig. 2.6 (the four descents)."""
    from articula.book.ch2.figures import convergence, manual_steps

    manual_steps(tuning.manual[FULL_KEY], FIG_2_5, out / "fig2_5.png")
    convergence({FIG_2_6[k]: r.result for k, r in tuning.auto.items()}, out / "fig2_6.png")


def _comparison_figures(comparison: Comparison, out: Path) -> None:
    """Figs. 2.7-2.9 (one trial per controller) and Fig. 2.10 (E against frequency)."""
    from articula.book.ch2.figures import error_summary, sinusoid_trials

    for f, (stem, label) in SINUSOID_FIGURES.items():
        ordered = {n: comparison.traces[f][n] for n in CONTROLLERS}
        title = f"{label}: one trial per controller at {f:g} Hz"
        sinusoid_trials(ordered, title, out / f"{stem}.png")
    ours = {n: [comparison.table[n][f] for f in FREQUENCIES] for n in CONTROLLERS}
    error_summary(FREQUENCIES, ours, BOOK_TABLE_2_3, out / "fig2_10.png")
