"""`articula emulate` and `articula rig`: the bench rigs of chapters 2-4 over serial."""

from __future__ import annotations

import dataclasses
import threading
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
    progress_bar,
)

rig_app = typer.Typer(no_args_is_help=True, help="A bench rig on a serial port.")
app.add_typer(rig_app, name="rig")
RIGS = ("pneunet", "six-chamber", "motor")
Port = Annotated[str, typer.Argument(help="The rig's serial port, e.g. /dev/ttyACM0.")]


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
            "encoder the emulated rig has (default: chapter 4's)."
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
    from articula.errors import ConfigError

    if rig not in RIGS:
        raise ConfigError("RIG", f"no emulator for {rig!r}; choose one of {', '.join(RIGS)}")
    if plant is not None and rig != "motor":
        raise ConfigError("--plant", "only the motor rig takes a plant config")
    if firmware is not None:
        if faults:
            raise ConfigError(
                "--faults",
                "faults are injected by the Python device, not on "
                "firmware; leave out --firmware or --faults",
            )
        emulator = _firmware_rig(rig, firmware, plant, realtime)
    else:
        from articula.rigs.emulator import Emulator, Faults

        emulator = Emulator(_device(rig, plant), realtime, Faults.parse(faults), seed).start()
    out.print(f"{rig} rig at {emulator.path} (Ctrl-C stops it)")
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        if firmware is not None:
            emulator.close()
        else:
            emulator.stop()


def _motor_config(plant: Path | None):
    """The motor.current config of --plant (chapter 4's defaults without one)."""
    from articula.experiments.motor import CurrentControlConfig
    from articula.validation import load_toml, parse_model

    data = {} if plant is None else load_toml(plant)
    data.pop("experiment", None)
    return parse_model(CurrentControlConfig, data, str(plant or "defaults"))


def _device(rig: str, plant: Path | None):
    """The Python device of an emulated rig."""
    if rig == "motor":
        from articula.book.ch4.rig import emulated_motor

        return emulated_motor(_motor_config(plant))
    if rig == "pneunet":
        from articula.rigs.pneunet import PneuNetDevice

        return PneuNetDevice()
    from articula.rigs.six_chamber import SixChamberDevice

    return SixChamberDevice()


def _firmware_rig(rig: str, elf: Path, plant: Path | None, realtime: bool):
    """The rig's firmware in the AVR emulator on its simulated plant."""
    from articula.rigs.firmware import FirmwareRig

    if rig == "motor":
        from articula.book.ch4.rig import firmware_motor

        pins = firmware_motor(_motor_config(plant))
    elif rig == "pneunet":
        from articula.rigs.pneunet import PneuNetPins

        pins = PneuNetPins()
    else:
        from articula.rigs.six_chamber import SixChamberPins

        pins = SixChamberPins()
    return FirmwareRig(elf, pins, realtime)


@rig_app.command()
def info(port: Port, as_json: JsonFlag = False) -> None:
    """Show what is on the port: rig kind, protocol and firmware versions, channels.

    \b
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
        "reset": i.reset.name.lower().replace("_", "-"),
    }
    if as_json:
        emit_json(summary)
        return
    out.print(
        f"{summary['rig']} rig on {port}: protocol {i.protocol}, firmware "
        f"{summary['firmware']}, a sample every {i.sample_period_us} µs"
    )
    for c in i.channels:
        out.print(escape(f"  {c.name} [{c.unit}]"))
    out.print(f"last started by: {summary['reset']}")


RIG_RUNS = {  # experiment -> (its driver, the rig it needs)
    "pneunet.pid": ("articula.book.ch2.rig", "PNEUNET"),
    "softarm.damping": ("articula.book.ch3.rig", "SIX_CHAMBER"),
    "motor.current": ("articula.book.ch4.rig", "MOTOR"),
}


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
    import importlib

    from articula.errors import ConfigError
    from articula.rigs.link import Link
    from articula.rigs.protocol import RigKind
    from articula.rigs.recorder import Recorder
    from articula.runs.folders import check_out, claimed
    from articula.runs.registry import config_to_dict, parse_config, with_absolute_paths
    from articula.validation import load_toml

    data = with_absolute_paths(load_toml(config), config.parent)
    if data.get("experiment") == "rig.record":
        _repeat_recording(port, data, config, out_dir, force, as_json)
        return
    exp, cfg = parse_config(data, str(config))
    if exp.name not in RIG_RUNS:
        raise ConfigError(
            "experiment", f"{exp.name} does not run on a rig yet; rig runs: {', '.join(RIG_RUNS)}"
        )
    module, rig = RIG_RUNS[exp.name]
    driver = importlib.import_module(module)
    # The folder is checked before the rig is touched and made only once the rig has answered
    # as the right kind: a refused run leaves nothing behind.
    check_out(out_dir, "run", force)
    with Link(port, RigKind[rig]) as link, claimed(out_dir, "run", force):
        recorder = Recorder(out_dir, config_to_dict(exp, cfg), driver.channels(link.info))
        record = recorder.capture(lambda: driver.run_on_rig(cfg, link, recorder), link.stats)
    if as_json:
        emit_json(record)
        return
    print_table(f"{exp.name} on {port}", ("metric", "value"), metric_rows(record["metrics"]))
    lost = record["link"]
    out.print(
        f"{record['samples']} samples; line: {lost['crc_errors']} damaged, "
        f"{lost['dropped']} lost, {lost['resends']} resent; in {out_dir}"
    )


def _repeat_recording(
    port: str, data: dict, config: Path, out_dir: Path, force: bool, as_json: bool
) -> None:
    """`rig run` of a recording's config.toml: its settings sent, its run again."""
    from articula.rigs.link import Link
    from articula.rigs.recorder import Recorder
    from articula.rigs.recording import parse_recording
    from articula.rigs.run import run_program
    from articula.runs.folders import check_out, claimed

    recording = parse_recording(data, str(config))
    check_out(out_dir, "run", force)
    with Link(port, recording["rig"]) as link, claimed(out_dir, "run", force):
        recorder = Recorder(out_dir, data, [c.name for c in link.info.channels])

        def take() -> dict[str, float]:
            for kind, body in recording["bodies"]:
                link.command(kind, body)
            run_program(link, recording["duration"], recording["seed"], recorder.add)
            return {}  # a recording has no metrics

        summary = recorder.capture(take, link.stats)
    if as_json:
        emit_json(summary)
        return
    out.print(f"{summary['samples']} samples as recorded in {config} in {out_dir}")


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
    from articula.rigs.link import Link
    from articula.rigs.recorder import Recorder
    from articula.rigs.recording import recording_config
    from articula.rigs.run import run_program
    from articula.runs.folders import check_out, claimed

    check_out(out_dir, "run", force)
    with Link(port) as link, claimed(out_dir, "run", force):
        channels = [c.name for c in link.info.channels]
        recorder = Recorder(out_dir, recording_config(link, duration, seed), channels)

        def take() -> dict[str, float]:
            run_program(link, duration, seed, recorder.add)
            return {}  # a recording has no metrics

        summary = recorder.capture(take, link.stats)
    if as_json:
        emit_json(summary)
        return
    out.print(f"{summary['samples']} samples of {', '.join(channels)} in {out_dir}")


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
        str,
        typer.Option(
            help="Reference levels [deg], comma-separated (manual and "
            "ziegler-nichols: a step to the first)."
        ),
    ] = "30,60",
    index: Annotated[int, typer.Option(min=0, help="Which run of the config's seeds.")] = 0,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Tune the PneuNet rig's PID with chapter 2's tuners, one experiment on the rig per
    probe (counted live); writes tuning.json.

    \b
    Example: articula rig tune /dev/ttyACM0 --method descent --levels 30,60 --out runs/tuning"""
    import json

    from articula.book.ch2.rig import TUNERS, tune_on_rig
    from articula.book.ch2.tuning import TuningConfig
    from articula.book.study import packaged
    from articula.errors import ConfigError
    from articula.rigs.link import Link
    from articula.rigs.protocol import RigKind
    from articula.runs.folders import TUNING, check_out, claimed
    from articula.runs.records import atomic_write
    from articula.validation import load_toml, parse_model

    if method not in TUNERS:
        raise ConfigError(
            "--method", f"unknown tuner {method!r}; choose one of {', '.join(TUNERS)}"
        )
    try:
        chosen = tuple(float(v) for v in levels.split(","))
    except ValueError:
        raise ConfigError(
            "--levels", f"comma-separated angles in degrees (got {levels!r})"
        ) from None
    data = load_toml(config or packaged("ch2", "tuning_quick.toml"))
    tuning = parse_model(TuningConfig, data, str(config or "tuning_quick.toml"))
    check_out(out_dir, "run", force)
    with Link(port, RigKind.PNEUNET) as link, claimed(out_dir, "run", force):
        with progress_bar(as_json) as bar:
            task = bar.add_task(f"{method}: experiments on the rig", total=None)
            result = tune_on_rig(tuning, link, method, chosen, index, lambda: bar.advance(task))
        result["link"] = dataclasses.asdict(link.stats)
        atomic_write(out_dir / TUNING, json.dumps(result, indent=2).encode())
    if as_json:
        emit_json(result)
        return
    kp, ki, kd = result["gains"]
    out.print(
        f"{method}: K_p = {kp:.4g}, K_i = {ki:.4g}, K_d = {kd:.4g} after "
        f"{result['experiments']} experiments; in {out_dir / TUNING}"
    )
