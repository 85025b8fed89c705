"""benchmarks/rig_link.py runs at a small size and prints its keys as one JSON object."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.mark.slow
def test_rig_link_benchmark_prints_its_keys():
    proc = subprocess.run(
        [sys.executable, str(BENCHMARKS / "rig_link.py"), "--json", "--commands", "50",
         "--seconds", "20"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    m = json.loads(proc.stdout)
    for key in ("roundtrip_ms_p50", "roundtrip_ms_p99", "telemetry_hz", "raw_roundtrip_ms_p50"):
        assert m[key] > 0
    assert m["telemetry_frames"] == m["telemetry_expected"] == 600  # 20 s at 30 Hz, none lost
    assert m["dropped_frames"] == m["crc_errors"] == 0
