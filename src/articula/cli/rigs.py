"""`articula emulate` and `articula rig`: the bench rigs of chapters 2-4 over serial."""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import Force, JsonFlag, OutDir, app, emit_json, out, print_table

rig_app = typer.Typer(no_args_is_help=True, help="A bench rig on a serial port.")
app.add_typer(rig_app, name="rig")
RIGS = ("pneunet",)  # the rigs an emulator exists for (six-chamber and motor: next)
Port = Annotated[str, typer.Argument(help="The rig's serial port, e.g. /dev/ttyACM0.")]


@app.command()
def emulate(
    rig: Annotated[str, typer.Argument(help="pneunet.")],
    realtime: Annotated[
        bool,
        typer.Option(
            "--realtime/--fast",
            help="Pace samples at the rig's period, or run them as fast as the host reads.",
        ),
    ] = False,
    faults: Annotated[
        str, typer.Option(help="e.g. drop=0.01,corrupt=0.01,delay_ms=20,reset_at=5.0")
    ] = "",
    seed: Annotated[int, typer.Option(min=0, help="Seed of the faults' draws.")] = 0,
) -> None:
    """Start a simulated rig behind a pseudo-terminal and print its device path.

    Example: articula emulate pneunet --fast, then articula rig info <the path it prints>"""
    from articula.errors import ConfigError
    from articula.rigs.emulator import Emulator, Faults
    from articula.rigs.pneunet import PneuNetDevice

    if rig not in RIGS:
        raise ConfigError("RIG", f"no emulator for {rig!r}; choose one of {', '.join(RIGS)}")
    emulator = Emulator(PneuNetDevice(), realtime, Faults.parse(faults), seed).start()
    out.print(f"{rig} rig at {emulator.path} (Ctrl-C stops it)")
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        emulator.stop()


@rig_app.command()
def info(port: Port, as_json: JsonFlag = False) -> None:
    """Show what is on the port: rig kind, protocol and firmware versions, channels.

    Example: articula rig info /dev/ttyACM0"""
    from rich.markup import escape  # "[deg]" is a unit, not rich markup

    from articula.rigs.link import Link

    with Link(port) as link:
        i = link.info
    summary = {
        "port": port,
        "rig": i.rig.name.lower().replace("_", "-"),
        "protocol": i.protocol,
        "firmware": ".".join(map(str, i.firmware)),
        "sample_period_s": i.sample_period_us * 1e-6,
        "channels": [{"name": c.name, "unit": c.unit} for c in i.channels],
    }
    if as_json:
        emit_json(summary)
        return
    out.print(f"{summary['rig']} rig on {port}: protocol {i.protocol}, firmware "
              f"{summary['firmware']}, a sample every {i.sample_period_us} µs")  # fmt: skip
    for c in i.channels:
        out.print(escape(f"  {c.name} [{c.unit}]"))


RIG_RUNS = {"pneunet.pid": ("articula.book.ch2.rig", "PNEUNET")}  # experiment -> driver, rig


@rig_app.command("run")
def run_(
    port: Port,
    config: Annotated[Path, typer.Argument(help="An experiment config, as `articula run` takes.")],
    out_dir: OutDir,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run an experiment config on the rig; the run folder is written as samples arrive.

    Example: articula rig run /dev/ttyACM0 my_pid.toml --out runs/rig (a pneunet.pid config)"""
    import importlib

    from articula.errors import ConfigError
    from articula.rigs.link import Link
    from articula.rigs.protocol import RigKind
    from articula.rigs.recorder import Recorder
    from articula.runs.folders import claimed
    from articula.runs.registry import config_to_dict, parse_config, with_absolute_paths
    from articula.validation import load_toml

    data = with_absolute_paths(load_toml(config), config.parent)
    exp, cfg = parse_config(data, str(config))
    if exp.name not in RIG_RUNS:
        raise ConfigError("experiment", f"{exp.name} does not run on a rig yet; rig runs: "
                          f"{', '.join(RIG_RUNS)}")  # fmt: skip
    module, rig = RIG_RUNS[exp.name]
    driver = importlib.import_module(module)
    with claimed(out_dir, "run", force), Link(port, RigKind[rig]) as link:
        recorder = Recorder(out_dir, config_to_dict(exp, cfg), driver.CHANNELS)
        try:
            metrics = driver.run_on_rig(cfg, link, recorder)
        except BaseException as exc:  # whatever stops the run, what was received is kept
            why = "interrupted (Ctrl-C)" if isinstance(exc, KeyboardInterrupt) else str(exc)
            recorder.finish({}, link.stats, incomplete=why)
            raise
        record = recorder.finish(metrics, link.stats)
    if as_json:
        emit_json(record)
        return
    rows = [(k, f"{v:.6g}") for k, v in record["metrics"].items()]
    print_table(f"{exp.name} on {port}", ("metric", "value"), rows)
    lost = record["link"]
    out.print(f"{record['samples']} samples; line: {lost['crc_errors']} damaged, "
              f"{lost['dropped']} lost, {lost['resends']} resent; in {out_dir}")  # fmt: skip
