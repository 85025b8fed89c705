"""`articula reproduce`: run each chapter's experiments and write OUT/report.md with figures."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from articula.errors import ConfigError
from articula.experiments.records import atomic_write, make_folder, package_versions

Progress = Callable[[int, int], None]
# A chapter section runs its experiments into OUT/<chapter>/ and returns its markdown and the
# numbers that `reproduce --json` reports under chapters.<name>.
Section = Callable[[Path, bool, int, Progress], tuple[str, dict[str, Any]]]


def _sections() -> dict[str, tuple[str, Section]]:
    """Chapters that can be reproduced today, in report order."""
    from articula.experiments.ch1_report import ch1_section
    from articula.experiments.ch2_report import ch2_section
    from articula.experiments.ch3_report import ch3_section
    from articula.experiments.ch4_report import ch4_section

    return {
        "ch1": ("Chapter 1: obstacle avoidance of a redundant arm (BAORNN)", ch1_section),
        "ch2": ("Chapter 2: PID control of a soft bending actuator (PneuNet)", ch2_section),
        "ch3": ("Chapter 3: six-chamber soft actuator and active oscillation damping", ch3_section),
        "ch4": ("Chapter 4: DC motor torque (current) control", ch4_section),
    }


def check_chapter(chapter: str) -> None:
    """Reject a chapter that cannot be reproduced yet."""
    sections = _sections()
    if chapter != "all" and chapter not in sections:
        choices = ", ".join(["all", *sections])
        raise ConfigError(
            "chapter", f"{chapter!r} cannot be reproduced yet; choose one of: {choices}"
        )


def reproduce(
    chapter: str, out: Path, full: bool = False, workers: int = 1, progress: Progress | None = None
) -> dict[str, Any]:
    """Reproduce one chapter or all of them; returns a summary with the report's path."""
    sections = _sections()
    check_chapter(chapter)
    chosen = list(sections) if chapter == "all" else [chapter]
    make_folder(out)
    start = time.perf_counter()
    notify = progress or (lambda done, total: None)
    parts = [
        "# articula: reproduction of the book's experiments",
        "",
        f"Mode: {'full' if full else 'quick'}. Every number below comes from running the code; "
        "the book's value stands beside ours, and every difference is explained.",
        "",
        "Versions: " + ", ".join(f"{k} {v}" for k, v in package_versions().items()) + ".",
        "",
    ]
    chapters: dict[str, dict[str, Any]] = {}
    for name in chosen:
        title, section = sections[name]
        markdown, chapters[name] = section(out / name, full, workers, notify)
        parts += [f"## {title}", "", markdown, ""]
    report = out / "report.md"
    atomic_write(report, "\n".join(parts).encode())
    return {
        "report": str(report),
        "chapters": chapters,
        "mode": "full" if full else "quick",
        "wall_time_s": time.perf_counter() - start,
    }
