"""benchmarks/bundle_dispatch.py runs and prints its keys as one JSON object."""

from __future__ import annotations

import pytest

from tests.benchmarks.run import benchmark


@pytest.mark.slow
def test_bundle_dispatch_benchmark_prints_its_keys():
    m = benchmark("bundle_dispatch.py")
    for key in ("packed_us", "named_us", "flat_us", "named_over_packed"):
        assert m[key] > 0
