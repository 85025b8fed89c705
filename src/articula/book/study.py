"""What a chapter's study needs from its surroundings: where to write, how big, which backend.

A chapter runs its sweeps through the shared runner (`Study.sweep`), so they resume without
recomputing finished runs and run on a process pool or on Dask; a chapter's searches and
single what-if runs run in its own process.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from articula.book.claims import Claim
from articula.runs import records, runner

Progress = Callable[[int, int], None]


def no_progress(done: int, total: int) -> None:
    """A progress callback that shows nothing."""


@dataclass(frozen=True)
class Study:
    """One chapter's run of the reproduction.

    Attributes:
        out: the chapter's output folder (figures, sweeps and run folders go under it).
        full: full-size runs (more seeds, trials and iterations) instead of quick ones.
        workers: local worker processes for sweeps.
        dask: None, "local" or a tcp://HOST:PORT scheduler address for sweeps.
        progress: called with (done, total) as the chapter's work advances.
    """

    out: Path
    full: bool = False
    workers: int = 1
    dask: str | None = None
    progress: Progress = field(default=no_progress)

    @property
    def size(self) -> str:
        """The suffix of the packaged sweep files: "full" or "quick"."""
        return "full" if self.full else "quick"

    def sweep(
        self, configs: Sequence[Mapping[str, Any]], name: str, done: int = 0, total: int = 0
    ) -> pa.Table:
        """Run `configs` into OUT/name (resuming finished runs); progress counts from `done`
        of `total` (default: the sweep's own size). Returns results.parquet as a table.

        The report folder holding OUT was checked by reproduce, so the sweep folder is taken
        as it is (`force`): a report written by an older version is resumed, not refused.
        """
        total = total or done + len(configs)
        return runner.run_sweep(
            configs,
            self.out / name,
            workers=self.workers,
            dask=self.dask,
            force=True,
            progress=lambda d, _n: self.progress(done + d, total),
        )


def packaged(chapter: str, name: str) -> Path:
    """Path of a file shipped in book/<chapter>/configs/."""
    return Path(str(resources.files(f"articula.book.{chapter}") / "configs" / name))


def run_folder(sweep_dir: Path, config: Mapping[str, Any]) -> Path:
    """The run folder of `config` (complete or partial) inside a sweep folder."""
    return sweep_dir / records.config_hash(runner.normalized(config))


def read_trace(sweep_dir: Path, config: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The trace of `config`'s run inside a sweep folder."""
    return records.read_trace(run_folder(sweep_dir, config))


def read_metrics(sweep_dir: Path, config: Mapping[str, Any]) -> dict[str, float]:
    """The metrics of `config`'s run inside a sweep folder."""
    return records.read_record(run_folder(sweep_dir, config))["metrics"]


@dataclass(frozen=True)
class Section:
    """A chapter's part of the report: its markdown (without the claims), the numbers that
    `reproduce --json` reports under chapters.<ch>, and its claims."""

    markdown: str
    data: dict[str, Any]
    claims: tuple[Claim, ...]
