"""`articula reproduce`: run each chapter's study and write OUT/report.md with its figures."""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from articula.book.claims import claims_data, claims_markdown
from articula.book.study import Progress, Study, no_progress
from articula.errors import ConfigError
from articula.runs.folders import claimed
from articula.runs.records import atomic_write, package_versions

# Chapter -> title of its report section; each is the package articula.book.<chapter>, whose
# `reproduce(study) -> Section` runs it.
CHAPTERS = {
    "ch1": "Chapter 1: obstacle avoidance of a redundant arm (BAORNN)",
    "ch2": "Chapter 2: PID control of a soft bending actuator (PneuNet)",
    "ch3": "Chapter 3: six-chamber soft actuator and active oscillation damping",
    "ch4": "Chapter 4: DC motor torque (current) control",
}


def check_chapter(chapter: str) -> None:
    """Reject a chapter name that is neither a chapter nor "all"."""
    if chapter != "all" and chapter not in CHAPTERS:
        choices = ", ".join(["all", *CHAPTERS])
        raise ConfigError("chapter", f"unknown chapter {chapter!r}; choose one of: {choices}")


def reproduce(
    chapter: str,
    out: Path,
    full: bool = False,
    workers: int = 1,
    dask: str | None = None,
    progress: Progress | None = None,
    force: bool = False,
    stage: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Reproduce one chapter or all of them into `out`; returns a summary with the report's
    path and, under chapters.<ch>, each chapter's numbers, claims and claims_detail.

    `out` must be new, empty or a report folder of articula's (`force` accepts any); it is
    held while the chapters run. `stage` is called with each chapter's name and place
    ("ch2, 2 of 4") as it starts.
    """
    check_chapter(chapter)
    with claimed(out, "report", force):
        return _reproduce(
            chapter, out, full, workers, dask, progress or no_progress, stage or (lambda _: None)
        )


def _reproduce(
    chapter: str,
    out: Path,
    full: bool,
    workers: int,
    dask: str | None,
    progress: Progress,
    stage: Callable[[str], None],
) -> dict[str, Any]:
    """reproduce() inside the folder it holds."""
    chosen = list(CHAPTERS) if chapter == "all" else [chapter]
    start = time.perf_counter()
    parts = [
        "# articula: reproduction of the book's experiments",
        "",
        f"Mode: {'full' if full else 'quick'}. Every number below comes from running the code; "
        "the book's value stands beside ours, and every difference is explained. Each claim "
        "of the book is marked reproduced, not reproduced or inconclusive by the rule it states.",
        "",
        "Versions: " + ", ".join(f"{k} {v}" for k, v in package_versions().items()) + ".",
        "",
    ]
    chapters: dict[str, dict[str, Any]] = {}
    for k, name in enumerate(chosen):
        stage(f"{name}, {k + 1} of {len(chosen)}")
        study = Study(out / name, full, workers, dask, progress)
        section = importlib.import_module(f"articula.book.{name}").reproduce(study)
        chapters[name] = {**section.data, **claims_data(section.claims)}
        parts += [f"## {CHAPTERS[name]}", "", section.markdown, ""]
        parts += claims_markdown(section.claims, "The chapter's claims against our runs")
    report = out / "report.md"
    atomic_write(report, "\n".join(parts).encode())
    return {
        "report": str(report),
        "chapters": chapters,
        "mode": "full" if full else "quick",
        "wall_time_s": time.perf_counter() - start,
    }
