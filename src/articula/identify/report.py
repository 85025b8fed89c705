"""An identification's folder: identification.json (the constants, their standard errors, the
undetermined ones, the validation NRMSE), plant.toml (the fitted plant as a config that runs,
emulates and tunes like any other) and fit.png (measured against model)."""

from __future__ import annotations

import io
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import tomli_w
from matplotlib.figure import Figure

from articula.identify.fit import VALIDATION, Curve, Identification
from articula.runs.folders import IDENTIFICATION
from articula.runs.records import atomic_write


def summary(rig: str, identification: Identification, sources: Sequence[str]) -> dict[str, Any]:
    """What identification.json holds (and `--json` prints).

    Args:
        rig: the rig's name.
        identification: the fit and its validation.
        sources: the recording folders fitted, as given.

    Returns:
        rig, parameters (name -> value, SI), standard_errors, unidentifiable,
        validation_nrmse, start (the constants the fit started from), validation_fraction
        and recordings.
    """
    fit = identification.fit
    return {
        "rig": rig,
        "parameters": fit.values,
        "standard_errors": fit.standard_errors,
        "unidentifiable": list(fit.unidentifiable),
        "bounds": identification.bounds,
        "validation_nrmse": identification.validation_nrmse,
        "start": identification.start,
        "validation_fraction": VALIDATION,
        "recordings": list(sources),
    }


def write_identification(
    folder: Path,
    rig: str,
    identification: Identification,
    sources: Sequence[str],
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Write identification.json, plant.toml and fit.png into `folder` (which exists).

    Args:
        folder: the identification's folder.
        rig: the rig's name.
        identification: the fit and its validation.
        sources: the recording folders, as given.
        extra: further keys for identification.json (the encoder's window, an excitation).

    Returns:
        identification.json's content.
    """
    content = summary(rig, identification, sources) | dict(extra or {})
    toml = tomli_w.dumps(identification.plant)
    if identification.fit.unidentifiable:
        kept = ", ".join(identification.fit.unidentifiable)
        toml = f"# not determined by the data, kept where the fit started: {kept}\n" + toml
    atomic_write(folder / "plant.toml", toml.encode())
    _plot(folder / "fit.png", rig, identification.curves)
    atomic_write(folder / IDENTIFICATION, (json.dumps(content, indent=2) + "\n").encode())
    return content


def _plot(path: Path, rig: str, curves: Sequence[Curve]) -> None:
    """Measured against model on the first recording, its held-out part shaded."""
    fig = Figure(figsize=(8, 2.5 * len(curves) + 0.5))  # no pyplot: nothing global
    axes = fig.subplots(len(curves), 1, sharex=True, squeeze=False)[:, 0]
    for ax, curve in zip(axes, curves, strict=True):
        ax.plot(curve.t, curve.measured, lw=0.6, color="0.55", label="measured")
        ax.plot(curve.t, curve.model, lw=1.0, color="tab:blue", label="fitted model")
        ax.axvspan(curve.validation_from, curve.t[-1], color="tab:orange", alpha=0.12,
                   label="validation")  # fmt: skip
        ax.set_ylabel(curve.label)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title(f"{rig}: measured against the fitted model (shaded: held out of the fit)")
    fig.tight_layout()
    png = io.BytesIO()
    fig.savefig(png, format="png", dpi=110)
    atomic_write(path, png.getvalue())
