"""benchmarks/firmware.py builds the firmware, runs it in simavr and prints its keys."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.mark.slow
@pytest.mark.firmware
def test_firmware_benchmark_prints_its_keys(built):
    proc = subprocess.run([sys.executable, str(BENCHMARKS / "firmware.py"), "--json",
                           "--build", str(built)], capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    m = json.loads(proc.stdout)
    assert 0 < m["motor_loop_cycles_max"] < 16_000
    assert m["motor_loop_budget_fraction"] == m["motor_loop_cycles_max"] / 16_000
    for program in ("motor", "pneunet", "six_chamber"):
        assert 0 < m["flash_bytes"][program] < 256 * 1024
        assert 0 < m["ram_bytes"][program] < 8192
    assert m["firmware_run_s"] > 0 and m["simulation_run_s"] > 0
    for program in ("motor", "pneunet", "six_chamber"):  # issue 47: no byte dropped
        assert m["burst_trials"][program] >= 100
        assert m["burst_after_stop_lost_bytes"][program] == 0
        off = m["max_interrupts_off_cycles"][program]
        assert 0 < off["measured"] <= off["static"] <= 160
