"""The rigs' serial link over a pseudo-terminal (issue "Bench rigs over serial").

    python benchmarks/rig_link.py [--json] [--commands N] [--seconds S] [--busy-runs R]

`articula emulate pneunet --fast` runs in its own process, as a device would; this process
opens its pty with pyserial through articula.rigs.link.Link, as `articula rig` does:
  roundtrip_ms_p50, _p99   a command (STREAM) until its ACK is parsed, N times
  telemetry_hz             frames parsed per second during a --fast run of S simulated
                           seconds (the device sends as fast as the host reads), with
                           dropped_frames and crc_errors, the line's counts over the run
  motor_loop_ratio         telemetry_hz / 1000: how many 1 kHz motor loops' telemetry the
                           host keeps up with (target >= 2)
  raw_roundtrip_ms_p50     the baseline: one byte written to a pty and read back by an echo
                           process in the same setup, no protocol (what the line itself costs)
  busy_host_timeout_stops  with --busy-runs R: of R motor runs with a CPU hog on every core,
                           those the device stopped for a silent host (benchmarks/rig_busy.py,
                           the firmware in simavr where it is built; busy_* its other keys)
"""

from __future__ import annotations

import os
import signal
import statistics
import struct
import subprocess
import sys
import time
import tty
from pathlib import Path
from typing import Any

import numpy as np
from common import run

from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetDevice
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import Kind
from articula.rigs.run import run_program

ARTICULA = Path(sys.executable).parent / "articula"
ECHO = "import os, sys\nwhile True:\n    os.write(1, os.read(0, 1))\n"


def measure(commands: int, seconds: float, busy_runs: int = 0) -> dict[str, Any]:
    """The keys of the module's docstring."""
    device = subprocess.Popen([ARTICULA, "emulate", "pneunet", "--fast"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        path = device.stdout.readline().split(" at ")[1].split()[0]
        with Link(path) as link:
            times = []
            for _ in range(commands):
                start = time.perf_counter()
                link.command(Kind.STREAM, struct.pack("<H", 1))
                times.append(time.perf_counter() - start)
            link.command(Kind.SET_REFERENCE, Program(Shape.CONSTANT, (45.0,)).encode())
            before = link.stats.frames
            start = time.perf_counter()
            t, _ = run_program(link, seconds, 0)
            wall = time.perf_counter() - start
            expected = round(seconds / PneuNetDevice().params.pwm_period)
            m = {
                "commands": commands,
                "roundtrip_ms_p50": 1e3 * statistics.median(times),
                "roundtrip_ms_p99": 1e3 * float(np.percentile(times, 99)),
                "telemetry_frames": int(t.size),
                "telemetry_expected": expected,
                "telemetry_hz": (link.stats.frames - before) / wall,
                "dropped_frames": link.stats.dropped,
                "crc_errors": link.stats.crc_errors,
            }
    finally:
        device.send_signal(signal.SIGINT)
        device.wait(10)
    m["motor_loop_ratio"] = m["telemetry_hz"] / 1000.0
    m["raw_roundtrip_ms_p50"] = 1e3 * _raw_roundtrip(commands)
    if busy_runs:
        import rig_busy

        firmware = rig_busy.FIRMWARE.is_file()
        busy = rig_busy.measure(busy_runs, 2.0, 1, firmware, 0)
        m |= {f"busy_{key}": value for key, value in busy.items()}
    return m


def _raw_roundtrip(count: int) -> float:
    """Median seconds for one byte through a pty to an echo process and back."""
    master, slave = os.openpty()
    tty.setraw(slave)
    echo = subprocess.Popen([sys.executable, "-c", ECHO], stdin=slave, stdout=slave)
    try:
        times = []
        for _ in range(count):
            start = time.perf_counter()
            os.write(master, b"x")
            os.read(master, 1)
            times.append(time.perf_counter() - start)
        return statistics.median(times)
    finally:
        echo.kill()
        os.close(master)
        os.close(slave)


def table(m: dict[str, Any]) -> tuple[str, list[str], list[list[str]]]:
    """One row per measure, against its target."""
    rows = [
        ["command -> ACK p50 [ms]", f"{m['roundtrip_ms_p50']:.3f}", ""],
        ["command -> ACK p99 [ms]", f"{m['roundtrip_ms_p99']:.3f}", "<= 5"],
        ["raw pty echo p50 [ms] (baseline)", f"{m['raw_roundtrip_ms_p50']:.3f}", ""],
        ["telemetry parsed [frames/s]", f"{m['telemetry_hz']:.0f}", ">= 2000"],
        ["x the 1 kHz motor loop", f"{m['motor_loop_ratio']:.1f}", ">= 2"],
        ["frames received / sent", f"{m['telemetry_frames']} / {m['telemetry_expected']}", ""],
        ["lost / damaged", f"{m['dropped_frames']} / {m['crc_errors']}", "0 / 0"],
    ]
    if "busy_runs" in m:
        stops = f"{m['busy_host_timeout_stops']} of {m['busy_runs']}"
        rows.append(["runs stopped by the host timeout, every core busy", stops, "0"])
    return "rig link over a pseudo-terminal", ["measure", "value", "target"], rows


if __name__ == "__main__":
    run(__doc__, measure, table,
        commands={"type": int, "default": 1000, "help": "commands timed"},
        seconds={"type": float, "default": 600.0, "help": "seconds of telemetry"},
        busy_runs={"type": int, "default": 0,
                   "help": "motor runs with a CPU hog on every core (0: none)"})  # fmt: skip
