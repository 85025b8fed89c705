"""`articula identify RIG RECORDING...`: recordings read from their run folders, fitted, and
the identification written into its own folder."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from articula.errors import ConfigError
from articula.identify.motor import MotorRecording, identify_motor
from articula.identify.report import write_identification
from articula.runs.folders import TRACE, claimed
from articula.runs.records import read_trace

RIGS = ("motor",)  # the rigs whose models `identify` fits
DEFAULT_WINDOW = 50  # [samples] the motor firmware's encoder window (50 ms at 1 kHz)


def read_recordings(rig: str, folders: Sequence[Path]) -> list[MotorRecording]:
    """Each folder's trace.parquet as a recording the rig's fit takes.

    Args:
        rig: the rig's name.
        folders: run folders of `articula rig record / run / identify` (their trace.parquet).

    Returns:
        The recordings, in order.
    """
    if rig not in RIGS:
        raise ConfigError(
            "RIG",
            f"identify fits {', '.join(RIGS)} so far; the {rig} rig's fit is not built yet "
            "(issue 30)",
        )
    if not folders:
        raise ConfigError("RECORDING", "give at least one recording folder")
    recordings = []
    for folder in folders:
        if not (folder / TRACE).is_file():
            raise ConfigError("RECORDING", f"{folder} has no {TRACE}: give a rig run's folder")
        recordings.append(MotorRecording.from_columns(read_trace(folder), str(folder)))
    return recordings


def identify_into(
    rig: str,
    folders: Sequence[Path],
    out_dir: Path,
    window: int = DEFAULT_WINDOW,
    force: bool = False,
) -> dict[str, Any]:
    """Fit the rig's model to the recordings and write the identification into out_dir.

    Args:
        rig: the rig's name (motor).
        folders: the recordings' run folders.
        out_dir: the identification's folder (identification.json, plant.toml, fit.png).
        window: the encoder's window [samples] (0: the recorded speed is the true one).
        force: write into a folder holding other files.

    Returns:
        identification.json's content.
    """
    recordings = read_recordings(rig, folders)  # a bad recording fails before out_dir exists
    with claimed(out_dir, "identification", force):
        return fit_and_write(rig, folders, out_dir, window, recordings=recordings)


def fit_and_write(
    rig: str,
    folders: Sequence[Path],
    out_dir: Path,
    window: int,
    extra: Mapping[str, Any] | None = None,
    recordings: Sequence[MotorRecording] | None = None,
) -> dict[str, Any]:
    """Fit and write into out_dir, which the caller holds (runs.folders.claimed).

    Args:
        rig: the rig's name (motor).
        folders: the recordings' run folders.
        out_dir: the identification's folder.
        window: the encoder's window [samples].
        extra: further keys for identification.json.
        recordings: the recordings, already read from `folders`; None: read here.

    Returns:
        identification.json's content.
    """
    if recordings is None:
        recordings = read_recordings(rig, folders)
    identification = identify_motor(recordings, window)
    sources = [str(f) for f in folders]
    return write_identification(out_dir, rig, identification, recordings, window, sources, extra)
