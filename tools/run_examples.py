"""Run every example at its full (default) size and keep what it prints and draws for the docs.

    .venv/bin/python tools/run_examples.py [NAME ...]

writes docs/examples/output/<example>/output.txt (its printed output) and its figures beside it,
which the documentation's example pages include; whatever else an example writes (run
folders, meshes) is removed. Run it after changing an example.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUTPUT = ROOT / "docs/examples/output"
KEPT = {".png", ".txt"}  # what the pages show


def main(names: list[str]) -> None:
    """Run the named examples (all without names), each into its own output folder."""
    scripts = sorted((ROOT / "examples").glob("[0-9]*.py"))
    for script in scripts:
        if names and script.stem not in names:
            continue
        out = OUTPUT / script.stem
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir(parents=True)
        print(f"running {script.name} ...", flush=True)
        proc = subprocess.run(
            [sys.executable, script, "--out", out], capture_output=True, text=True,
            env=os.environ | {"MPLBACKEND": "Agg"}, cwd=ROOT, check=False,
        )  # fmt: skip
        if proc.returncode != 0:
            sys.exit(f"{script.name} failed:\n{proc.stderr}")
        (out / "output.txt").write_text(proc.stdout, encoding="utf-8")
        for path in list(out.iterdir()):
            if path.is_dir():
                shutil.rmtree(path)
            elif path.suffix not in KEPT:
                path.unlink()


if __name__ == "__main__":
    main(sys.argv[1:])
