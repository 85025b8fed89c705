"""Fixtures of the command-line tests."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from articula.runs import runner, sweep


@pytest.fixture(scope="module")
def sweep_cli(cli, one_json):
    """sweep_cli(spec, out, *options) runs `articula sweep ... --json`; returns its summary."""

    def run(spec_path: Path, out: Path, *options: str) -> dict:
        proc = cli("sweep", spec_path, "--out", out, *options, "--json")
        assert proc.returncode == 0, proc.stderr
        summary = one_json(proc.stdout)
        assert summary["runs"] == len(sweep.expand_sweep(tomllib.loads(spec_path.read_text())))
        assert Path(summary["results"]) == out / runner.RESULTS
        return summary

    return run
