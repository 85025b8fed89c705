"""benchmarks/drive.py drives the fake UR controller and prints its keys as one JSON object."""

from __future__ import annotations

import pytest

from tests.arms import robot_data
from tests.benchmarks.run import benchmark

pytest.importorskip("rtde_control", reason='needs ur-rtde: pip install -e ".[ur]"')
pytest.importorskip("mujoco", reason='the fake runs the twin: pip install -e ".[sim]"')


@pytest.mark.slow
def test_drive_benchmark_prints_its_keys():
    robot_data()  # the UR10 of example-robot-data (skips without it)
    m = benchmark("drive.py", "--duration", "3")
    assert m["contacts"] == 0 and m["ticks"] > 0
    assert 0 <= m["deadline_miss_fraction"] <= 1
    for key in ("latency_p99_ms", "tracking_rms_mm"):
        assert m[key] >= 0
