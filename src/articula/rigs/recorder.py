"""A rig run's folder, written while the run goes on: nothing received is lost.

Each sample is appended to `telemetry.csv` as it arrives (flushed at least every FLUSH_S),
so even a killed process leaves every sample up to the last flush. `finish` then writes the
normal run folder (config.toml, trace.parquet, record.json) from what was received, complete
or not: an interrupted run's record says `"complete": false` and why, beside the line's
losses (damaged frames, frames missing from the device's count, commands sent again).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from articula.rigs.link import LinkStats
from articula.runs.folders import JOURNAL
from articula.runs.records import build_record, make_folder, write_run
from articula.runs.registry import Result

FLUSH_S = 0.1  # [s] between flushes of the journal to the disk


class Recorder:
    """Telemetry rows (device time [s], then one value per channel) into `folder`.

    Args:
        folder: the run folder to write (created now, its journal opened).
        config: the run's configuration, written as its config.toml.
        channels: the telemetry channels' names, one per value of a row.
    """

    def __init__(self, folder: Path, config: Mapping[str, Any], channels: Sequence[str]) -> None:
        make_folder(folder)
        self.folder, self.config, self.channels = folder, dict(config), list(channels)
        self.t: list[float] = []
        self.rows: list[np.ndarray] = []
        self._journal = (folder / JOURNAL).open("w", encoding="ascii")
        self._journal.write(",".join(["t", *self.channels]) + "\n")
        self._flushed = time.monotonic()
        self._started = time.monotonic()

    def add(self, t: float, row: np.ndarray) -> None:
        """One sample: device time t [s] and its channel values.

        Args:
            t: the sample's device time since the run's start [s].
            row: one value per channel, shape (channels,).
        """
        self.t.append(t)
        self.rows.append(np.asarray(row, dtype=float))
        self._journal.write(",".join(f"{v:.9g}" for v in (t, *row)) + "\n")
        if time.monotonic() - self._flushed > FLUSH_S:
            self._journal.flush()
            self._flushed = time.monotonic()

    def columns(self) -> dict[str, np.ndarray]:
        """The samples so far as trace columns (t and one per channel).

        Returns:
            Column name -> values, shape (samples,): "t" [s], then each channel in its unit.
        """
        values = np.array(self.rows).reshape(-1, len(self.channels))
        return {"t": np.array(self.t), **dict(zip(self.channels, values.T, strict=True))}

    def capture(self, run: Callable[[], Mapping[str, float]], stats: LinkStats) -> dict[str, Any]:
        """Do `run` (which feeds `add` and returns the metrics) and write the run folder;
        whatever stops it, what was received is written, marked incomplete, and the error
        goes on.

        Args:
            run: the run on the rig: feeds `add` with each sample, returns the run's metrics.
            stats: the link's loss counters, recorded with the run.

        Returns:
            The run's record (record.json).
        """
        try:
            metrics = run()
        except BaseException as exc:
            why = "interrupted (Ctrl-C)" if isinstance(exc, KeyboardInterrupt) else str(exc)
            self.finish({}, stats, incomplete=why)
            raise
        return self.finish(metrics, stats)

    def finish(
        self, metrics: Mapping[str, float], stats: LinkStats, incomplete: str | None = None
    ) -> dict[str, Any]:
        """Write the run folder from the samples received.

        Args:
            metrics: the run's metrics (those of what was received when it ended early).
            stats: the link's loss counters, recorded under "link".
            incomplete: why the run ended early; None for a complete run.

        Returns:
            The run's record (record.json).
        """
        self._journal.close()
        record = build_record(
            self.config, Result(dict(metrics), {}), time.monotonic() - self._started
        )
        record["complete"] = incomplete is None
        if incomplete is not None:
            record["incomplete"] = incomplete
        record["samples"] = len(self.t)
        record["link"] = dataclasses.asdict(stats)
        write_run(self.folder, self.config, record, self.columns())
        return record
