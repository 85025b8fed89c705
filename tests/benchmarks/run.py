"""Run a script of benchmarks/ with --json in a subprocess and read its one JSON object."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def benchmark(script: str, *options: str, timeout: float = 600) -> dict:
    """benchmarks/`script` --json `options`: its measures (the run must succeed)."""
    proc = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), "--json", *options],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)
