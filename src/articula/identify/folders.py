"""`articula identify RIG RECORDING...`: recordings read from their run folders, fitted, and
the identification written into its own folder."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from articula.errors import ConfigError
from articula.identify.fit import Identification
from articula.identify.motor import MotorRecording, identify_motor
from articula.identify.pneunet import PneuNetRecording, identify_pneunet
from articula.identify.report import write_identification
from articula.identify.six_chamber import SixChamberRecording, identify_six_chamber
from articula.runs.folders import CONFIG, TRACE, check_out, claimed
from articula.runs.records import read_trace
from articula.validation import load_toml

RIGS = ("motor", "pneunet", "six-chamber")  # the rigs whose models `identify` fits
DEFAULT_WINDOW = 50  # [samples] the motor firmware's encoder window (50 ms at 1 kHz)


def identify_recordings(rig: str, folders: Sequence[Path], window: int) -> Identification:
    """Read each folder's trace.parquet and fit the rig's model to them.

    Args:
        rig: the rig's name (motor, pneunet or six-chamber).
        folders: run folders of `articula rig record / run / identify` (six-chamber: `rig
            record` folders, whose config.toml holds the actuation).
        window: the motor encoder's window [samples] (0: the recorded speed is the true one).

    Returns:
        The identification.
    """
    if rig not in RIGS:
        raise ConfigError("RIG", f"no rig called {rig!r}; choose one of {', '.join(RIGS)}")
    if not folders:
        raise ConfigError("RECORDING", "give at least one recording folder")
    traces = []
    for folder in folders:
        if not (folder / TRACE).is_file():
            raise ConfigError("RECORDING", f"{folder} has no {TRACE}: give a rig run's folder")
        traces.append((read_trace(folder), str(folder)))
    if rig == "motor":
        return identify_motor([MotorRecording.from_columns(*t) for t in traces], window)
    if rig == "pneunet":
        return identify_pneunet([PneuNetRecording.from_columns(*t) for t in traces])
    runs = [
        SixChamberRecording.from_run(columns, load_toml(Path(where) / CONFIG), where)
        for columns, where in traces
    ]
    return identify_six_chamber(runs)


def identify_into(
    rig: str,
    folders: Sequence[Path],
    out_dir: Path,
    window: int = DEFAULT_WINDOW,
    force: bool = False,
) -> dict[str, Any]:
    """Fit the rig's model to the recordings and write the identification into out_dir.

    Args:
        rig: the rig's name (motor, pneunet or six-chamber).
        folders: the recordings' run folders.
        out_dir: the identification's folder (identification.json, plant.toml, fit.png).
        window: the motor encoder's window [samples] (0: the recorded speed is the true one).
        force: write into a folder holding other files.

    Returns:
        identification.json's content.
    """
    check_out(out_dir, "identification", force)
    identification = identify_recordings(rig, folders, window)  # before out_dir exists
    with claimed(out_dir, "identification", force):
        return _write(rig, identification, folders, out_dir, window, None)


def fit_and_write(
    rig: str,
    folders: Sequence[Path],
    out_dir: Path,
    window: int,
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Fit and write into out_dir, which the caller holds (runs.folders.claimed).

    Args:
        rig: the rig's name (motor, pneunet or six-chamber).
        folders: the recordings' run folders.
        out_dir: the identification's folder.
        window: the motor encoder's window [samples].
        extra: further keys for identification.json (the excitation).

    Returns:
        identification.json's content.
    """
    identification = identify_recordings(rig, folders, window)
    return _write(rig, identification, folders, out_dir, window, extra)


def _write(rig, identification, folders, out_dir, window, extra) -> dict[str, Any]:
    """write_identification with the sources and, for the motor, the encoder's window."""
    extra = dict(extra or {}) | ({"encoder_window": window} if rig == "motor" else {})
    sources = [str(f) for f in folders]
    return write_identification(out_dir, rig, identification, sources, extra)
