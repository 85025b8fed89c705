"""An identification's folder: identification.json (the constants, their standard errors, the
undetermined ones, the validation NRMSE), plant.toml (the fitted plant as a config that runs,
emulates and tunes like any other) and fit.png (measured against model)."""

from __future__ import annotations

import io
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w
from matplotlib.figure import Figure

from articula.identify.motor import VALIDATION, Identification, MotorRecording, simulate
from articula.runs.folders import IDENTIFICATION
from articula.runs.records import atomic_write

DRIVER_VOLTAGE = 12.0  # [V] the H-bridge's supply (experiments/motor.py's pwm.v_max default)


def summary(
    rig: str, identification: Identification, window: int, sources: Sequence[str]
) -> dict[str, Any]:
    """What identification.json holds (and `--json` prints).

    Args:
        rig: the rig's name (motor).
        identification: the fit and its validation.
        window: the encoder's window the fit assumed [samples].
        sources: the recording folders fitted, as given.

    Returns:
        rig, parameters (name -> value, SI), standard_errors, unidentifiable,
        validation_nrmse, start (the book's constants the fit started from), encoder_window,
        validation_fraction and recordings.
    """
    fit = identification.fit
    return {
        "rig": rig,
        "parameters": fit.values,
        "standard_errors": fit.standard_errors,
        "unidentifiable": list(fit.unidentifiable),
        "validation_nrmse": identification.validation_nrmse,
        "start": identification.start,
        "encoder_window": window,
        "validation_fraction": VALIDATION,
        "recordings": list(sources),
    }


def plant_config(identification: Identification) -> dict[str, Any]:
    """The fitted motor as a motor.current config on the single rig (`articula emulate motor
    --plant`, `articula run`).

    Args:
        identification: the fit.

    Returns:
        The config's tables.
    """
    motor = identification.params()
    # A reference the fitted motor can hold at rest within the driver's 12 V: half its stall
    # current there (the book's 1 A at 5 rad/s is beyond a motor of twice the book's R).
    reference = {"current": round(0.5 * DRIVER_VOLTAGE / motor.R, 3), "speed": 0.0}
    return {
        "experiment": "motor.current",
        "rig": "single",
        "motor": motor.model_dump(),
        "reference": reference,
    }


def write_identification(
    folder: Path,
    rig: str,
    identification: Identification,
    recordings: Sequence[MotorRecording],
    window: int,
    sources: Sequence[str],
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Write identification.json, plant.toml and fit.png into `folder` (which exists).

    Args:
        folder: the identification's folder.
        rig: the rig's name.
        identification: the fit and its validation.
        recordings: the recordings fitted.
        window: the encoder's window the fit assumed [samples].
        sources: the recording folders, as given.
        extra: further keys for identification.json (a rig identification's excitation).

    Returns:
        identification.json's content.
    """
    content = summary(rig, identification, window, sources) | dict(extra or {})
    toml = tomli_w.dumps(plant_config(identification))
    if identification.fit.unidentifiable:
        kept = ", ".join(identification.fit.unidentifiable)
        toml = f"# not determined by the data, the book's values kept: {kept}\n" + toml
    atomic_write(folder / "plant.toml", toml.encode())
    _plot(folder / "fit.png", identification, recordings[0], window)
    atomic_write(folder / IDENTIFICATION, (json.dumps(content, indent=2) + "\n").encode())
    return content


def _plot(path: Path, identification: Identification, recording: MotorRecording, window: int):
    """Measured against model on the first recording, its held-out part shaded."""
    current, speed = simulate(identification.params(), recording, window)
    t = np.arange(recording.v1.size) * recording.dt
    cut = t[int(t.size * (1 - VALIDATION))]
    fig = Figure(figsize=(8, 5))  # no pyplot: nothing global, no backend to choose
    axes = fig.subplots(2, 1, sharex=True)
    rows = (("i_meas", current, "current [A]"), ("omega_meas", speed, "speed [rad/s]"))
    for ax, (channel, model, label) in zip(axes, rows, strict=True):
        ax.plot(t, getattr(recording, channel), lw=0.6, color="0.55", label="measured")
        ax.plot(t, model, lw=1.0, color="tab:blue", label="fitted model")
        ax.axvspan(cut, t[-1], color="tab:orange", alpha=0.12, label="validation")
        ax.set_ylabel(label)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title("motor: measured against the fitted model (first recording)")
    fig.tight_layout()
    png = io.BytesIO()
    fig.savefig(png, format="png", dpi=110)
    atomic_write(path, png.getvalue())
