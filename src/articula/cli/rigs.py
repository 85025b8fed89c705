"""`articula rig`: the bench rigs of chapters 2-4 over serial."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import (
    Force,
    JsonFlag,
    OutDir,
    app,
    emit_json,
    metric_rows,
    out,
    print_table,
)

rig_app = typer.Typer(no_args_is_help=True, help="A bench rig on a serial port.")
app.add_typer(rig_app, name="rig")
Port = Annotated[str, typer.Argument(help="The rig's serial port, e.g. /dev/ttyACM0.")]


@rig_app.command()
def info(port: Port, as_json: JsonFlag = False) -> None:
    """Show what is on the port: rig kind, protocol and firmware versions, channels.

    \b
    Example: articula rig info /dev/ttyACM0"""
    from rich.markup import escape  # "[deg]" is a unit, not rich markup

    from articula.experiments.rig_sessions import rig_info

    summary = rig_info(port)
    if as_json:
        emit_json(summary)
        return
    out.print(
        f"{summary['rig']} rig on {port}: protocol {summary['protocol']}, firmware "
        f"{summary['firmware']}, a sample every {summary['sample_period_s'] * 1e6:.0f} µs"
    )
    for c in summary["channels"]:
        out.print(escape(f"  {c['name']} [{c['unit']}]"))
    out.print(f"last started by: {summary['reset']}")


@rig_app.command("run")
def run_(
    port: Port,
    config: Annotated[Path, typer.Argument(help="An experiment config, as `articula run` takes.")],
    out_dir: OutDir,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run an experiment config on the rig; the run folder is written as samples arrive.

    A `rig record` folder's config.toml (experiment "rig.record") runs again with the settings
    it recorded.

    \b
    Example: articula rig run /dev/ttyACM0 my_pid.toml --out runs/rig"""
    from articula.experiments.rig_sessions import run_config

    record = run_config(port, config, out_dir, force)
    if as_json:
        emit_json(record)
        return
    if record["experiment"] == "rig.record":
        out.print(f"{record['samples']} samples as recorded in {config} in {out_dir}")
        return
    print_table(
        f"{record['experiment']} on {port}", ("metric", "value"), metric_rows(record["metrics"])
    )
    lost = record["link"]
    out.print(
        f"{record['samples']} samples; line: {lost['crc_errors']} damaged, "
        f"{lost['dropped']} lost, {lost['resends']} resent; in {out_dir}"
    )


@rig_app.command()
def record(
    port: Port,
    duration: Annotated[float, typer.Option(min=0.001, help="Seconds to record [s].")],
    out_dir: OutDir,
    seed: Annotated[int, typer.Option(min=0, help="Noise seed of an emulated rig.")] = 0,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run the rig with what it holds (gains, reference) and record every channel.

    The settings it ran (read back from the rig) go into the folder's config.toml, which
    `articula rig run` takes to repeat the recording.

    \b
    Example: articula rig record /dev/ttyACM0 --duration 10 --out runs/record"""
    from articula.experiments.rig_sessions import record as record_rig

    summary = record_rig(port, duration, out_dir, seed, force)
    if as_json:
        emit_json(summary)
        return
    out.print(f"{summary['samples']} samples of {', '.join(summary['channels'])} in {out_dir}")
