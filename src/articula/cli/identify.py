"""`articula identify` and `articula rig identify`: a rig's model fitted to its recordings."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from articula.cli.app import (
    Force,
    JsonFlag,
    OutDir,
    app,
    emit_json,
    out,
    progress_bar,
)
from articula.cli.realtime import RtPriority, use_realtime
from articula.cli.rigs import Port, rig_app

Window = Annotated[
    int,
    typer.Option(
        min=0,
        max=100_000,
        help="The encoder's speed window [samples] (the motor firmware's: 50; 0: true speed).",
    ),
]


@app.command()
def identify(
    rig: Annotated[
        str, typer.Argument(help="The rig whose model to fit: motor, pneunet or six-chamber.")
    ],
    recordings: Annotated[
        list[Path], typer.Argument(help="Run folders of the rig (rig record / run / identify).")
    ],
    out_dir: OutDir,
    encoder_window: Window = 50,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Fit the rig's model to recordings; writes identification.json, plant.toml, fit.png.

    The last quarter of each recording is kept out of the fit and its NRMSE printed.

    \b
    Example: articula identify motor runs/ident/excitation_* --out runs/refit"""
    from articula.identify.folders import identify_into

    _show(identify_into(rig, recordings, out_dir, encoder_window, force), out_dir, as_json)


@rig_app.command("identify")
def rig_identify(
    port: Port,
    out_dir: OutDir,
    seed: Annotated[int, typer.Option(min=0, help="Noise seed of an emulated rig.")] = 0,
    encoder_window: Window = 50,
    rt_priority: RtPriority = None,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run an excitation designed for identification on the rig (motor or PneuNet, as it
    reports), record it, fit its model.

    Each part of the excitation is a run folder out/excitation_<k>; its amplitudes are in
    identification.json.

    \b
    Example: articula rig identify /dev/ttyACM0 --out runs/ident"""
    from articula.experiments.rig_identify import identify_on_rig

    use_realtime(rt_priority)
    with progress_bar(as_json) as bar:
        task = bar.add_task("excitation on the rig: parts", total=None)
        summary = identify_on_rig(
            port, out_dir, seed, encoder_window, force, lambda: bar.advance(task)
        )
    _show(summary, out_dir, as_json)


def _show(summary: dict[str, Any], out_dir: Path, as_json: bool) -> None:
    """Print the constants with their standard errors and the validation NRMSE (or JSON)."""
    if as_json:
        emit_json(summary)
        return
    for name, value in summary["parameters"].items():
        error = summary["standard_errors"][name]
        out.print(f"{name} = {value:.5g} ± {error:.2g}")
    for name in summary["unidentifiable"]:
        bound = summary["bounds"].get(name)
        out.print(f"{name}: not determined by the data" + (f" ({bound})" if bound else ""))
    fits = ", ".join(f"{c} {v:.3f}" for c, v in summary["validation_nrmse"].items())
    out.print(f"validation NRMSE: {fits}; plant config {out_dir / 'plant.toml'}")
