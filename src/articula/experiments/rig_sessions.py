"""Sessions on a bench rig over serial (`articula rig info / run / record`): open the line,
check the rig is the kind asked for, record every sample into a run folder, close.

A run folder is checked before the rig is touched and made only once the rig has answered as
the right kind: a refused run leaves nothing behind.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from articula.experiments.rig_registry import rig_running
from articula.rigs.link import Link
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.rigs.recording import EXPERIMENT, parse_recording, recording_config
from articula.rigs.run import run_program
from articula.runs.folders import check_out, claimed
from articula.runs.registry import config_to_dict, parse_config, with_absolute_paths
from articula.validation import load_toml


def _word(name: str) -> str:
    """An enum member's name as the CLI writes it (SIX_CHAMBER -> six-chamber)."""
    return name.lower().replace("_", "-")


def rig_info(port: str) -> dict[str, Any]:
    """What the rig on `port` says of itself.

    Args:
        port: The rig's serial port.

    Returns:
        {"port", "rig", "protocol", "firmware" ("major.minor"), "sample_period_s",
        "channels": [{"name", "unit"}], "reset" (what last started it)}.
    """
    with Link(port) as link:
        i = link.info
    return {
        "port": port,
        "rig": _word(i.rig.name),
        "protocol": i.protocol,
        "firmware": ".".join(map(str, i.firmware)),
        "sample_period_s": i.sample_period_us * 1e-6,
        "channels": [{"name": c.name, "unit": c.unit} for c in i.channels],
        "reset": _word(i.reset.name),
    }


def run_config(port: str, config: Path, out_dir: Path, force: bool = False) -> dict[str, Any]:
    """Run an experiment config on the rig on `port`, written to `out_dir` as samples arrive.

    A recording's config.toml (experiment "rig.record") runs again with the settings it
    recorded.

    Args:
        port: The rig's serial port.
        config: An experiment config, as `articula run` takes, or a recording's config.toml.
        out_dir: The run folder (refused as `articula run` refuses one, unless `force`).
        force: Overwrite a run folder that holds other files.

    Returns:
        The run's record (record.json); a recording's has no metrics.
    """
    data = with_absolute_paths(load_toml(config), config.parent)
    if data.get("experiment") == EXPERIMENT:
        r = parse_recording(data, str(config))
        return _session(port, r["rig"], out_dir, force, data, r["bodies"], r["duration"], r["seed"])
    exp, cfg = parse_config(data, str(config))
    rig = rig_running(exp.name)
    check_out(out_dir, "run", force)
    with Link(port, rig.kind) as link, claimed(out_dir, "run", force):
        recorder = Recorder(out_dir, config_to_dict(exp, cfg), rig.channels(link.info))
        return recorder.capture(lambda: rig.run_on_rig(cfg, link, recorder), link.stats)


def record(
    port: str, duration: float, out_dir: Path, seed: int = 0, force: bool = False
) -> dict[str, Any]:
    """Run the rig with what it holds (gains, reference) and record every channel; the
    settings it ran, read back from the rig, go into the folder's config.toml, which
    `run_config` takes to repeat the recording.

    Args:
        port: The rig's serial port.
        duration: How long to record [s].
        out_dir: The run folder (refused as `articula run` refuses one, unless `force`).
        seed: The noise seed of an emulated rig.
        force: Overwrite a run folder that holds other files.

    Returns:
        The recording's record (record.json; no metrics), with "channels" added.
    """
    return _session(port, None, out_dir, force, None, (), duration, seed)


def _session(
    port: str,
    kind: RigKind | None,
    out_dir: Path,
    force: bool,
    config: Mapping[str, Any] | None,
    bodies: tuple | list,
    duration: float,
    seed: int,
) -> dict[str, Any]:
    """Send `bodies`, run the rig's program for `duration` and record it (config None: the
    rig's settings as read back)."""
    check_out(out_dir, "run", force)
    with Link(port, kind) as link, claimed(out_dir, "run", force):
        channels = [c.name for c in link.info.channels]
        recorder = Recorder(out_dir, config or recording_config(link, duration, seed), channels)

        def take() -> dict[str, float]:
            for command, body in bodies:
                link.command(command, body)
            run_program(link, duration, seed, recorder.add)
            return {}  # a recording has no metrics

        summary = recorder.capture(take, link.stats)
    return {**summary, "channels": channels}
