"""Every script in examples/ runs to the end at reduced size (``--quick``) and shows something.

Each example takes ``--quick`` (a reduced size for CI) and ``--out DIR`` (where its figures and
files go). An example whose first lines say ``# needs: chromium`` (or ``# needs: firmware``)
skips, naming the apt-get line, on a machine without that system part.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("[0-9]*.py"))
SYSTEM_PARTS = {
    "chromium": (lambda: shutil.which("chromium") is not None, "apt-get install -y chromium"),
    "firmware": (
        lambda: shutil.which("avr-gcc") is not None and shutil.which("simavr") is not None,
        "apt-get install -y gcc-avr avr-libc simavr libsimavr-dev",
    ),
}


def needs(script: Path) -> list[str]:
    """The system parts the script's header says it needs."""
    head = script.read_text(encoding="utf-8").splitlines()[:20]
    return [p.strip() for line in head if line.startswith("# needs:") for p in line[8:].split(",")]


def test_there_are_about_ten_examples():
    assert len(EXAMPLES) >= 10


@pytest.mark.slow
@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_at_reduced_size(script, tmp_path):
    for part in needs(script):
        present, install = SYSTEM_PARTS[part]
        if not present():
            pytest.skip(install)
    env = os.environ | {"MPLBACKEND": "Agg"}
    proc = subprocess.run(
        [sys.executable, script, "--quick", "--out", tmp_path],
        capture_output=True, text=True, timeout=600, cwd=tmp_path, env=env,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.strip(), "an example prints what it found"
    figures = list(tmp_path.rglob("*.png"))
    assert figures, "an example draws what it found"
    assert all(p.stat().st_size > 0 for p in figures)
    for figure in figures:  # and says where each one went
        assert figure.name in proc.stdout, figure
