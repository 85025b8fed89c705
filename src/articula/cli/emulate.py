"""`articula emulate`: a simulated bench rig behind a pseudo-terminal."""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import app, out
from articula.cli.realtime import RtPriority, use_realtime


@app.command()
def emulate(
    rig: Annotated[str, typer.Argument(help="pneunet, six-chamber, motor or ur.")],
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
    scene: Annotated[
        Path | None, typer.Option(help="ur: the scene file whose arm the controller has.")
    ] = None,
    host: Annotated[
        str, typer.Option(help="ur: the address to listen on (ports 29999, 30001-30004).")
    ] = "127.0.0.1",
    start: Annotated[
        str | None,
        typer.Option(help="ur: the arm's joints at power-on [rad], comma separated (robot.q0)."),
    ] = None,
    log: Annotated[
        Path | None, typer.Option(help="ur: write the controller's log here (Parquet) at the end.")
    ] = None,
    rt_priority: RtPriority = None,
) -> None:
    """Start a simulated bench rig behind a pseudo-terminal and print its device path, or
    (ur) a fake Universal Robots controller that speaks RTDE, running the scene's arm.

    Point `articula rig info / run / record / tune` at the path it prints, or `articula
    drive SCENE --arm ur:HOST` at the fake's address.

    \b
    Example: articula emulate motor --firmware firmware/build/motor.elf
    Example: articula emulate ur --scene ur10.toml --host 127.0.0.2"""
    from articula.signals import terminate_as_interrupt

    use_realtime(rt_priority)  # before any thread starts: they inherit it
    if rig == "ur":
        _emulate_ur(scene, host, start, log)
        return
    from articula.experiments.rig_registry import rig_named

    emulator = rig_named(rig).emulated(plant, firmware, realtime, faults, seed)
    with terminate_as_interrupt(), emulator:  # Ctrl-C or SIGTERM: the rig stops, 130 or 143
        out.print(f"{rig} rig at {emulator.path} (Ctrl-C stops it)")
        threading.Event().wait()


def _emulate_ur(scene: Path | None, host: str, start: str | None, log: Path | None) -> None:
    """Serve the fake UR controller until Ctrl-C (130) or SIGTERM (143)."""
    from articula.errors import ConfigError
    from articula.experiments.ur_fake import serve_fake_ur
    from articula.signals import terminate_as_interrupt

    if scene is None:
        raise ConfigError("--scene", "emulate ur needs the scene file whose arm it runs")
    try:
        joints = None if start is None else [float(v) for v in start.split(",")]
    except ValueError:
        raise ConfigError(
            "--start", f"needs numbers [rad], comma separated (got {start!r})"
        ) from None
    with terminate_as_interrupt():
        serve_fake_ur(scene, host, joints, log, lambda line: out.print(line, soft_wrap=True))
