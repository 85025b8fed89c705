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
from articula.cli.realtime import RtPriority, use_realtime

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
    rt_priority: RtPriority = None,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run an experiment config on the rig; the run folder is written as samples arrive.

    The same config is then simulated (its [plant]: `identify`'s plant.toml, or the one `rig
    tune --model` wrote into tuned.toml) and the rig's metrics are shown beside the model's
    (--json: under model_metrics). A `rig record` folder's config.toml (experiment
    "rig.record") runs again with the settings it recorded.

    \b
    Example: articula rig run /dev/ttyACM0 runs/tuning/tuned.toml --out runs/rig"""
    from articula.experiments.rig_sessions import run_config

    use_realtime(rt_priority)
    record = run_config(port, config, out_dir, force)
    model = None if record["experiment"] == "rig.record" else _on_the_model(config)
    if as_json:
        emit_json(record if model is None else record | {"model_metrics": model})
        return
    if model is None:
        out.print(f"{record['samples']} samples as recorded in {config} in {out_dir}")
        return
    rig_rows, model_rows = dict(metric_rows(record["metrics"])), dict(metric_rows(model))
    print_table(
        f"{record['experiment']} on {port} and on its model ([plant] of {config.name})",
        ("metric", "rig", "model"),
        [(k, rig_rows.get(k, "—"), model_rows.get(k, "—")) for k in rig_rows | model_rows],
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
    rt_priority: RtPriority = None,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run the rig with what it holds (gains, reference) and record every channel.

    The settings it ran (read back from the rig) go into the folder's config.toml, which
    `articula rig run` takes to repeat the recording.

    \b
    Example: articula rig record /dev/ttyACM0 --duration 10 --out runs/record"""
    from articula.experiments.rig_sessions import record as record_rig

    use_realtime(rt_priority)
    summary = record_rig(port, duration, out_dir, seed, force)
    if as_json:
        emit_json(summary)
        return
    out.print(f"{summary['samples']} samples of {', '.join(summary['channels'])} in {out_dir}")


def _on_the_model(config: Path) -> dict[str, float | str | None]:
    """The config's metrics simulated in this process (no folder written)."""
    from articula.runs.registry import with_absolute_paths
    from articula.runs.runner import execute
    from articula.validation import load_toml

    data = with_absolute_paths(load_toml(config), config.parent)
    return execute(data, where=str(config)).record["metrics"]
