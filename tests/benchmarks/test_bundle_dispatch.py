"""benchmarks/bundle_dispatch.py runs and prints its keys as one JSON object."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def test_bundle_dispatch_benchmark_prints_its_keys():
    proc = subprocess.run(
        [sys.executable, str(BENCHMARKS / "bundle_dispatch.py"), "--json"],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    m = json.loads(proc.stdout)
    for key in ("packed_us", "named_us", "flat_us", "named_over_packed"):
        assert m[key] > 0
