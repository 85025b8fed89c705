"""A recording on a rig (`articula rig record`): the settings the rig held, read back with GET,
written into the run folder's config.toml, so that `articula rig run` of that file sends them
again and repeats the recording.

    experiment = "rig.record"
    rig = "motor"                 # pneunet | six-chamber | motor
    duration = 2.0                # [s]
    seed = 0
    [settings.gains]              # motor: kp, ki, filter_order, kp_speed, ki_speed
    kp = 10.0                     # pneunet: schedule = "constant", rows = [[kp, ki, kd, point]]
    [settings.reference]          # every rig: shape (constant, steps, sinusoid, actuation,
    shape = "current"             # current) and its numbers (rigs/programs.py)
    values = [1.0, 0.0, 0.0, 5.0]
    # [settings.damping] delta, start, length (six-chamber); [settings.output] value (pneunet)
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from articula.control.pid import GainSchedule
from articula.errors import ConfigError
from articula.rigs.link import Link
from articula.rigs.pneunet import SCHEDULES, decode_gains, encode_gains
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import Kind, RigKind

EXPERIMENT = "rig.record"
RIGS = {"pneunet": RigKind.PNEUNET, "six-chamber": RigKind.SIX_CHAMBER, "motor": RigKind.MOTOR}
MOTOR_GAINS = ("kp", "ki", "filter_order", "kp_speed", "ki_speed")
DAMPING = ("delta", "start", "length")


def _reference(body: bytes) -> dict[str, Any]:
    """SET_REFERENCE's body, readable."""
    program = Program.decode(body)
    return {"shape": program.shape.name.lower(), "values": list(program.values)}


def _reference_body(table: Mapping[str, Any]) -> bytes:
    """SET_REFERENCE's body from its table."""
    return Program(Shape[str(table["shape"]).upper()], tuple(map(float, table["values"]))).encode()


def _pneunet_gains(body: bytes) -> dict[str, Any]:
    """The PneuNet's SET_GAINS body, readable."""
    schedule = decode_gains(body)
    points = np.broadcast_to(schedule.points, (len(schedule.gains),))
    return {
        "schedule": schedule.kind,
        "rows": [
            [*map(float, row), float(p)] for row, p in zip(schedule.gains, points, strict=True)
        ],
    }


def _pneunet_gains_body(table: Mapping[str, Any]) -> bytes:
    """The PneuNet's SET_GAINS body from its table."""
    rows = np.asarray(table["rows"], dtype=float).reshape(-1, 4)
    if table["schedule"] not in SCHEDULES:
        raise ValueError(f"schedule is one of {', '.join(SCHEDULES)}")
    points = rows[:, 3] if table["schedule"] != "constant" else np.zeros(1)
    return encode_gains(GainSchedule(table["schedule"], rows[:, :3], points))


def _floats(names: tuple[str, ...]) -> tuple[Callable[[bytes], dict], Callable[[Mapping], bytes]]:
    """A setting of named float32s: (body to table, table to body)."""
    form = f"<{len(names)}f"
    return (
        lambda body: dict(zip(names, map(float, struct.unpack(form, body)), strict=True)),
        lambda table: struct.pack(form, *(float(table[n]) for n in names)),
    )


def _output(body: bytes) -> dict[str, Any] | None:
    """The PneuNet's SET_OUTPUT body, readable; None when it holds none (-1)."""
    _, value = struct.unpack("<Bf", body)
    return None if value < 0 else {"value": float(value)}


# Per rig: setting name -> (its command, body to table, table to body).
CODECS: dict[RigKind, dict[str, tuple[Kind, Callable, Callable]]] = {
    RigKind.PNEUNET: {
        "gains": (Kind.SET_GAINS, _pneunet_gains, _pneunet_gains_body),
        "reference": (Kind.SET_REFERENCE, _reference, _reference_body),
        "output": (Kind.SET_OUTPUT, _output, lambda t: struct.pack("<Bf", 0, float(t["value"]))),
    },
    RigKind.MOTOR: {
        "gains": (Kind.SET_GAINS, *_floats(MOTOR_GAINS)),
        "reference": (Kind.SET_REFERENCE, _reference, _reference_body),
    },
    RigKind.SIX_CHAMBER: {
        "reference": (Kind.SET_REFERENCE, _reference, _reference_body),
        "damping": (Kind.SET_DAMPING, *_floats(DAMPING)),
    },
}


def recording_config(link: Link, duration: float, seed: int) -> dict[str, Any]:
    """The config of a recording of what the rig behind `link` holds now (GET per setting).

    Args:
        link: the line to the rig.
        duration: the recording's length [s].
        seed: the noise seed of an emulated rig.

    Returns:
        The rig.record config (module docstring), ready for config.toml.
    """
    rig = link.info.rig
    settings = {}
    for name, (kind, readable, _) in CODECS[rig].items():
        table = readable(link.setting(kind))
        if table is not None:
            settings[name] = table
    words = {kind: word for word, kind in RIGS.items()}
    return {
        "experiment": EXPERIMENT,
        "rig": words[rig],
        "duration": duration,
        "seed": seed,
        "settings": settings,
    }


def parse_recording(data: Mapping[str, Any], where: str) -> dict[str, Any]:
    """A rig.record config checked: its rig, duration, seed and each setting's body.

    Args:
        data: the config as read from its file.
        where: the file, named in errors.

    Returns:
        {"rig": RigKind, "duration": s, "seed": int, "bodies": [(command, body), ...]}.
    """
    unknown = set(data) - {"experiment", "rig", "duration", "seed", "settings"}
    if unknown:
        raise ConfigError(
            f"{where}: {sorted(unknown)[0]}",
            "unknown key; a rig.record config has rig, duration, seed and [settings]",
        )
    if data.get("rig") not in RIGS:
        raise ConfigError(f"{where}: rig", f"one of {', '.join(RIGS)}")
    duration, seed = data.get("duration"), data.get("seed", 0)
    if not isinstance(duration, int | float) or not 0 < duration < 1e6 or math.isnan(duration):
        raise ConfigError(f"{where}: duration", "a number of seconds in (0, 1e6)")
    if not isinstance(seed, int) or not 0 <= seed < 2**32:
        raise ConfigError(f"{where}: seed", "an integer in [0, 2^32)")
    rig = RIGS[data["rig"]]
    bodies = []
    for name, table in dict(data.get("settings", {})).items():
        if name not in CODECS[rig]:
            raise ConfigError(
                f"{where}: settings.{name}",
                f"a {data['rig']} rig's settings are {', '.join(CODECS[rig])}",
            )
        kind, _, body = CODECS[rig][name]
        try:
            bodies.append((kind, body(table)))
        except (KeyError, TypeError, ValueError, struct.error) as exc:
            raise ConfigError(f"{where}: settings.{name}", f"does not read ({exc})") from None
    return {"rig": rig, "duration": float(duration), "seed": seed, "bodies": bodies}
