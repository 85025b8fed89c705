"""`articula emulate`: a simulated bench rig behind a pseudo-terminal."""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import app, out


@app.command()
def emulate(
    rig: Annotated[str, typer.Argument(help="pneunet, six-chamber or motor.")],
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
    plant: Annotated[
        Path | None,
        typer.Option(
            help="motor: a motor.current config whose rig, motor, dt, PWM, sensor and "
            "encoder the emulated rig has; pneunet: a pneunet.pid config whose [plant] it "
            "has; six-chamber: a softarm.damping config whose [actuator] it has (default: "
            "the book's; `articula identify` writes one as plant.toml)."
        ),
    ] = None,
    firmware: Annotated[
        Path | None,
        typer.Option(
            help="Run this firmware ELF (firmware/build/<rig>.elf, `make -C firmware`) in the "
            "simavr AVR emulator, its pins on the simulated plant, instead of the Python "
            "device."
        ),
    ] = None,
) -> None:
    """Start a simulated rig behind a pseudo-terminal and print its device path.

    Point `articula rig info / run / record / tune` at the path it prints.

    \b
    Example: articula emulate motor --firmware firmware/build/motor.elf"""
    from articula.experiments.rig_registry import rig_named
    from articula.signals import terminate_as_interrupt

    emulator = rig_named(rig).emulated(plant, firmware, realtime, faults, seed)
    with terminate_as_interrupt(), emulator:  # Ctrl-C or SIGTERM: the rig stops, 130 or 143
        out.print(f"{rig} rig at {emulator.path} (Ctrl-C stops it)")
        threading.Event().wait()
