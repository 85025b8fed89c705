"""Speed of the chapter-2 comparison: the full Table 2.3 sweep and the batch speed-up.

    python benchmarks/pid_sweep.py [--json] [--workers N]

full_sweep_s: wall time of the full Table 2.3 sweep, six controllers × seven frequencies ×
25 trials = 1,050 closed-loop runs (42 batched sweep points), through `runs.runner.run_sweep`
into a fresh temporary folder with N local worker processes (default 2), gains from the book's
Table 2.2. Target <= 60 s on 2 cores.
batch_speedup: wall time per trial of 25 trials run one by one (25 calls of the registered
experiment with trials = 1 and seeds 0-24) divided by the same 25 trials as one batch (one
call with trials = 25), for the 0.5 Hz run of the fuzzy PID; both in this process, each
the fastest of five timings taken in turns. Target >= 20. The ratio is bounded by the batch
size, 25: with a per-step cost c that a batch pays once (Python, the PID and plant calls) and
a cost v per trial and step, it is 25 (c + v) / (c + 25 v) < 25 (cache effects aside). A
value near 25 says the loop is overhead-bound and batching removes nearly all of it; it is not
a figure that can keep growing.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from common import run

from articula.book.ch2.book_values import BOOK_TABLE_2_2, CONTROLLERS
from articula.book.study import packaged
from articula.experiments.pneunet import (
    AngleReference,
    ControllerConfig,
    PneuNetPidConfig,
    run_pneunet_pid,
)
from articula.runs.runner import run_sweep
from articula.runs.sweep import expand_sweep
from articula.validation import load_toml

TRIALS = 25
SWEEP = packaged("ch2", "table2_3_full.toml")


def _book_controllers() -> list[dict[str, object]]:
    """The six controllers with the book's tuned gains (Table 2.2 and Fig. 2.6a)."""
    points = [15.0, 45.0, 75.0]
    tables = []
    for name in CONTROLLERS:
        kind, method = name.split("-")
        book = BOOK_TABLE_2_2[method]
        if kind == "ordinary":
            gains = [book["sequence"] if method == "auto" else book["45"]]
            tables.append({"name": name, "schedule": "constant", "gains": gains})
        else:
            rows = [book[f"{p:g}"] for p in points]
            schedule = "piecewise" if kind == "piecewise" else "fuzzy"
            tables.append({"name": name, "schedule": schedule, "gains": rows, "points_deg": points})
    return tables


def _full_sweep_seconds(workers: int) -> tuple[float, int]:
    spec = load_toml(SWEEP)
    spec["grid"] = {"controller": _book_controllers()}
    configs = expand_sweep(spec)
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        run_sweep(configs, Path(tmp) / "sweep", workers=workers)
        return time.perf_counter() - start, sum(c["trials"] for c in configs)


def _best_times(fns: list, repeats: int) -> list[float]:
    """Fastest of `repeats` timings of each function, taken in turns (after one warm-up each):
    load from other processes only ever adds time, and taking turns spreads it over all."""
    for fn in fns:
        fn()
    best = [float("inf")] * len(fns)
    for _ in range(repeats):
        for k, fn in enumerate(fns):
            start = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - start)
    return best


def _batch_speedup() -> tuple[float, float, float]:
    """(one by one [s], batch [s], ratio) for TRIALS trials of the 0.5 Hz fuzzy run."""
    rows = [BOOK_TABLE_2_2["auto"][k] for k in ("15", "45", "75")]
    config = PneuNetPidConfig(
        trials=TRIALS, duration=10.0, reference=AngleReference(frequency=0.5),
        controller=ControllerConfig(name="fuzzy-auto", schedule="fuzzy", gains=rows),
    )  # fmt: skip
    singles = [config.model_copy(update={"seed": s, "trials": 1}) for s in range(TRIALS)]

    def one_by_one() -> None:
        for single in singles:
            run_pneunet_pid(single)

    t_single, t_batch = _best_times([one_by_one, lambda: run_pneunet_pid(config)], repeats=5)
    return t_single, t_batch, t_single / t_batch


def measure(workers: int) -> dict[str, object]:
    """Run both timings and return the figures."""
    t_single, t_batch, speedup = _batch_speedup()
    sweep_s, runs = _full_sweep_seconds(workers)
    return {
        "full_sweep_s": sweep_s,
        "full_sweep_runs": runs,
        "workers": workers,
        "one_by_one_s": t_single,
        "batch_s": t_batch,
        "batch_speedup": speedup,
    }


def table(m: dict) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        [f"full_sweep_s ({m['full_sweep_runs']} closed-loop runs, {m['workers']} workers)",
         f"{m['full_sweep_s']:.1f}", "<= 60"],
        [f"{TRIALS} trials one by one, 10 s each [s]", f"{m['one_by_one_s']:.3f}", ""],
        [f"one batch of {TRIALS} trials [s]", f"{m['batch_s']:.3f}", ""],
        ["batch_speedup", f"{m['batch_speedup']:.1f}", ">= 20"],
    ]  # fmt: skip
    title = "chapter-2 PID comparison (simulated PneuNet, 30 Hz loop)"
    return title, ["measure", "value", "target"], rows


if __name__ == "__main__":
    run(
        __doc__,
        measure,
        table,
        workers={"type": int, "default": 2, "help": "local worker processes"},
    )
