"""Fixtures shared by the book's tests."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest


@pytest.fixture(scope="session")
def reproduced_ch4(cli, one_json, tmp_path_factory) -> tuple[Path, dict[str, Any]]:
    """`articula reproduce ch4 --out DIR --json` (quick mode), run once: (DIR, summary)."""
    out = tmp_path_factory.mktemp("reproduce") / "report"
    # The linearised bandwidth study does thousands of small dense solves; multithreaded
    # OpenBLAS on a busy 2-core machine makes that many times slower, so pin it to one thread.
    proc = cli("reproduce", "ch4", "--out", out, "--json", env={"OPENBLAS_NUM_THREADS": "1"})
    assert proc.returncode == 0, proc.stderr
    return out, one_json(proc.stdout)
