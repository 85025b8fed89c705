"""benchmarks/servo.py runs and prints its keys as one JSON object."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def test_servo_benchmark_prints_its_keys():
    proc = subprocess.run(
        [sys.executable, str(BENCHMARKS / "servo.py"), "--json"],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    m = json.loads(proc.stdout)
    assert m["periods"] == 1000
    for key in ("servo_stream_us", "qp_step_us", "stream_over_step"):
        assert m[key] > 0
