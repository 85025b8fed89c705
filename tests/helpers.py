"""Small helpers shared by test modules of several folders."""

from __future__ import annotations

from pathlib import Path

import tomli_w


def hidden_files(folder: Path) -> list[Path]:
    """Every file or folder below `folder` whose name starts with '.' (temporary files)."""
    return [p for p in folder.rglob("*") if p.name.startswith(".")]


def write_spec(path: Path, spec: dict) -> Path:
    """Write a sweep (or config) mapping as TOML to `path`; returns `path`."""
    path.write_text(tomli_w.dumps(spec))
    return path


def run_folders(out: Path) -> list[str]:
    """Names of the run folders inside a sweep folder, sorted."""
    return sorted(p.name for p in out.iterdir() if p.is_dir())
