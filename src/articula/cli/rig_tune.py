"""`articula rig tune`: chapter 2's tuners on the PneuNet rig, optionally on a fitted model
first."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import (
    Force,
    JsonFlag,
    OutDir,
    emit_json,
    out,
    progress_bar,
)
from articula.cli.realtime import RtPriority, use_realtime
from articula.cli.rigs import Port, rig_app


@rig_app.command()
def tune(
    port: Port,
    out_dir: OutDir,
    method: Annotated[
        str, typer.Option(help="descent (Algorithm 1), manual or ziegler-nichols.")
    ] = "descent",
    config: Annotated[
        Path | None,
        typer.Option(help="A chapter-2 tuning config (default: the book's quick one)."),
    ] = None,
    levels: Annotated[
        str, typer.Option(help="Reference levels [deg], comma-separated (manual, Z-N: the first).")
    ] = "30,60",
    index: Annotated[int, typer.Option(min=0, help="Which run of the config's seeds.")] = 0,
    model: Annotated[
        Path | None,
        typer.Option(
            help="A fitted PneuNet (`articula rig identify`'s plant.toml): tune on it in "
            "simulation, then confirm on the rig with a few experiments (descent only)."
        ),
    ] = None,
    rt_priority: RtPriority = None,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Tune the PneuNet rig's PID with chapter 2's tuners, one experiment on the rig per
    probe (counted live); writes tuning.json and tuned.toml (a pneunet.pid config of the
    tuned gains, with the fitted plant of --model, for `rig run` and `run`).

    \b
    Example: articula rig tune /dev/ttyACM0 --method descent --levels 30,60 --out runs/tuning
    On a fitted model first: ... --model runs/ident/plant.toml"""
    from articula.book.ch2.rig_tuning import parse_levels, tune_into

    chosen = parse_levels(levels)
    use_realtime(rt_priority)
    with progress_bar(as_json) as bar:
        task = bar.add_task(f"{method}: experiments on the rig", total=None)
        result = tune_into(
            out_dir, port, method, config, chosen, index, force, lambda: bar.advance(task), model
        )
    if as_json:
        emit_json(result)
        return
    kp, ki, kd = result["gains"]
    cost = f", M = {result['cost']:.4g}" if "cost" in result else ""
    on_model = f" and {result['model_experiments']} on the model" if model else ""
    out.print(
        f"{method}: K_p = {kp:.4g}, K_i = {ki:.4g}, K_d = {kd:.4g}{cost} after "
        f"{result['experiments']} experiments on the rig{on_model}; in {out_dir / 'tuning.json'}"
        f" and {out_dir / result['tuned']} (rig run PORT / run take it)"
    )
