"""`articula emulate` and `articula rig`: the bench rigs of chapters 2-4 over serial."""

from __future__ import annotations

import threading
from typing import Annotated

import typer

from articula.cli.app import JsonFlag, app, emit_json, out

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
