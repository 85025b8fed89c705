"""benchmarks/twin.py runs and prints its keys as one JSON object."""

from __future__ import annotations

import pytest

from tests.benchmarks.run import benchmark

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"')


@pytest.mark.slow
def test_twin_benchmark_prints_its_keys():
    m = benchmark("twin.py")
    assert m["periods"] == 1000
    for key in ("twin_realtime_factor", "servo_stream_us", "twin_period_us", "qp_step_us"):
        assert m[key] > 0
