"""Chapter 3's packaged configs run through the command line as they say."""

from __future__ import annotations

import pytest

from articula.book.study import packaged


@pytest.mark.slow
def test_delta_sweep_file_runs_through_articula_sweep(cli, tmp_path):
    proc = cli("sweep", packaged("ch3", "delta_quick.toml"), "--out", tmp_path / "sweep", "--json")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "sweep" / "results.parquet").is_file()


def test_timed_pulse_file_runs_through_articula_run(cli, tmp_path):
    proc = cli("run", packaged("ch3", "timed_pulse.toml"), "--out", tmp_path / "run", "--json")
    assert proc.returncode == 0, proc.stderr
