"""Rig runs on a host whose every core is busy: how many the device stops for a silent host.

    python benchmarks/rig_busy.py [--json] [--runs N] [--seconds S] [--hogs-per-core K]
                                  [--firmware] [--rt-priority P]

A motor rig is emulated (`articula emulate motor`, or with --firmware its firmware in simavr,
firmware/build/motor.elf), and this process is its host, as `articula rig run` is: N runs of
Fig. 4.5's motor.current config, S seconds each, while K processes per core spin at ordinary
priority (a CPU hog on every core). The device ends a run on its own when the host sends
nothing for host_timeout_ms (500 ms: ERROR code 5); every such run counts:
  host_timeout_stops       runs the device stopped for a silent host, of --runs
  late_runs                runs that did not end within their duration + 10 s (the host
                           gave up: an emulator starved of the CPU)
  other_failures           runs that failed otherwise
  run_wall_s_p50           a run's wall time, median [s]
With --rt-priority P a second lane runs the host under SCHED_FIFO at P (`rig run
--rt-priority`); the lanes alternate run by run, the first drawn at random; its keys are
prefixed rt_. The emulator plays a device, which has a CPU of its own: with --rt-priority it
runs under SCHED_FIFO at P + 10 in both lanes, so that the lanes differ in the host alone.
Target (issue 47): 0 stopped in 20 with a hog on every core.
"""

from __future__ import annotations

import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import tomli_w
from common import run

from articula.arms.realtime import use_ordinary, use_realtime
from articula.book.study import packaged
from articula.errors import DeviceError
from articula.experiments.rig_sessions import run_config
from articula.validation import load_toml

ARTICULA = Path(sys.executable).parent / "articula"
FIRMWARE = Path(__file__).resolve().parents[1] / "firmware" / "build" / "motor.elf"
HOG = "while True: pass"


def measure(
    runs: int, seconds: float, hogs_per_core: int, firmware: bool, rt_priority: int
) -> dict[str, Any]:
    """The keys of the module's docstring."""
    device = [ARTICULA, "emulate", "motor"] + (["--firmware", str(FIRMWARE)] if firmware else [])
    if rt_priority:  # the device has a CPU of its own: the emulator runs above the hogs too
        device += ["--rt-priority", str(rt_priority + 10)]
    emulator = subprocess.Popen(device, stdout=subprocess.PIPE, text=True)
    hogs = [subprocess.Popen([sys.executable, "-c", HOG])
            for _ in range(hogs_per_core * (os.cpu_count() or 1))]  # fmt: skip
    lanes = [0, rt_priority] if rt_priority else [0]
    random.SystemRandom().shuffle(lanes)
    outcomes: dict[int, list[tuple[str, float]]] = {lane: [] for lane in lanes}
    try:
        port = emulator.stdout.readline().split(" at ")[1].split()[0]
        with tempfile.TemporaryDirectory() as tmp:
            config = Path(tmp) / "motor.toml"
            data = load_toml(packaged("ch4", "fig4_5.toml"))
            data |= {"duration": seconds, "settle": seconds / 2}
            config.write_text(tomli_w.dumps(data))
            for k in range(runs * len(lanes)):
                lane = lanes[k % len(lanes)]
                outcomes[lane].append(_one_run(port, config, Path(tmp) / f"run{k}", lane))
    finally:
        for process in [*hogs, emulator]:
            process.kill()
            process.wait()
    m: dict[str, Any] = {"runs": runs, "hogs": len(hogs), "firmware": firmware}
    for lane, results in outcomes.items():
        prefix = "rt_" if lane else ""
        m[prefix + "host_timeout_stops"] = sum(kind == "host timeout" for kind, _ in results)
        m[prefix + "late_runs"] = sum(kind == "late" for kind, _ in results)
        m[prefix + "other_failures"] = sum(kind == "failed" for kind, _ in results)
        m[prefix + "run_wall_s_p50"] = statistics.median(wall for _, wall in results)
    return m


def _one_run(port: str, config: Path, out: Path, priority: int) -> tuple[str, float]:
    """One run as `rig run` does it, the host under SCHED_FIFO at `priority` (0: ordinary)."""
    if priority:
        use_realtime(priority)
    start = time.perf_counter()
    try:
        record = run_config(port, config, out)
        kind = "done" if record["complete"] else "failed"
    except DeviceError as exc:
        kind = "host timeout" if "(code 5)" in str(exc) else "failed"
        kind = "late" if "did not end within" in str(exc) else kind
    finally:
        use_ordinary()
    return kind, time.perf_counter() - start


def table(m: dict[str, Any]) -> tuple[str, list[str], list[list[str]]]:
    """One row per lane."""
    rows = []
    for prefix, lane in (("", "ordinary"), ("rt_", "SCHED_FIFO")):
        if prefix + "host_timeout_stops" in m:
            rows.append([lane, f"{m[prefix + 'host_timeout_stops']} of {m['runs']}",
                         str(m[prefix + "late_runs"]), str(m[prefix + "other_failures"]),
                         f"{m[prefix + 'run_wall_s_p50']:.2f}"])  # fmt: skip
    title = f"rig runs with {m['hogs']} CPU hogs ({'firmware' if m['firmware'] else 'Python'})"
    columns = ["host", "stopped by the host timeout", "late", "other failures", "run wall [s]"]
    return title, columns, rows


if __name__ == "__main__":
    run(__doc__, measure, table,
        runs={"type": int, "default": 20, "help": "runs per lane"},
        seconds={"type": float, "default": 2.0, "help": "each run's duration [s]"},
        hogs_per_core={"type": int, "default": 1, "help": "spinning processes per core"},
        firmware={"action": "store_true", "help": "the motor firmware in simavr"},
        rt_priority={"type": int, "default": 0,
                     "help": "a lane with the host under SCHED_FIFO too (0: none)"})  # fmt: skip
