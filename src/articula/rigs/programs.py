"""Reference programs a rig runs by itself: a few numbers on the line instead of a sample per
control period (SET_REFERENCE, docs/protocol.md).

constant: (value,); steps: (hold [s], level, level, ...) each level held `hold` seconds, the
last one to the end; sinusoid: (offset, amplitude, frequency [Hz]): offset − amplitude ·
cos(2π f t), which starts at rest, as chapter 2's reference does; actuation (the six-chamber
rig's): (side [deg], gauge pressure [Pa], hold [s]): fill that side, hold, vent at `hold`;
current (the motor rig's): (current [A], amplitude [A], frequency [rad/s], speed [rad/s]):
i_ref = current + amplitude · sin(frequency · t), the load motor holding the speed.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from articula.errors import ConfigError, DeviceError
from articula.rigs.protocol import MAX_FRAME, pack_floats, unpack_floats


class Shape(IntEnum):
    """Kinds of reference program."""

    CONSTANT = 0
    STEPS = 1
    SINUSOID = 2
    ACTUATION = 3
    CURRENT = 4


MAX_VALUES = (MAX_FRAME - 3 - 2 - 2) // 4  # header, CRC, shape and count bytes


@dataclass(frozen=True)
class Program:
    """A reference program: its shape and numbers (module docstring).

    Attributes:
        shape: the kind of program.
        values: its numbers, as the shape takes them (module docstring).
    """

    shape: Shape
    values: tuple[float, ...]

    def __post_init__(self) -> None:
        need = {Shape.CONSTANT: 1, Shape.SINUSOID: 3, Shape.ACTUATION: 3, Shape.CURRENT: 4}.get(
            self.shape
        )
        if need is not None and len(self.values) != need:
            raise ConfigError("program", f"a {self.shape.name.lower()} takes {need} numbers")
        if self.shape == Shape.STEPS and not 2 <= len(self.values) <= MAX_VALUES:
            raise ConfigError("program", f"steps take a hold time and 1-{MAX_VALUES - 1} levels")
        if self.shape == Shape.STEPS and not self.values[0] > 0:
            raise ConfigError("program", f"the hold time must be > 0 (got {self.values[0]})")
        if not all(math.isfinite(v) for v in self.values):
            raise ConfigError("program", "numbers must be finite")

    def at(self, t: np.ndarray | float) -> np.ndarray:
        """The reference at times t [s].

        Args:
            t: times since the run's start [s], a scalar or any shape.

        Returns:
            The reference at each time, t's shape (the unit of the program's levels).
        """
        t = np.asarray(t, dtype=float)
        v = self.values
        if self.shape == Shape.ACTUATION:
            raise ConfigError("program", "an actuation has no reference value over time")
        if self.shape == Shape.CURRENT:
            return v[0] + v[1] * np.sin(v[2] * t)
        if self.shape == Shape.CONSTANT:
            return np.full(t.shape, v[0])
        if self.shape == Shape.SINUSOID:
            return v[0] - v[1] * np.cos(2 * math.pi * v[2] * t)
        levels = np.asarray(v[1:])
        # A sample time n·T lands on a boundary up to rounding: count it as the next level's.
        index = np.floor(t / v[0] + 1e-9).astype(int)
        return levels[np.clip(index, 0, levels.size - 1)]

    def encode(self) -> bytes:
        """The body of SET_REFERENCE: shape u8, count u8, the numbers as float32.

        Returns:
            The message's body, 2 + 4 · count bytes.
        """
        return struct.pack("<BB", self.shape, len(self.values)) + pack_floats(self.values)

    @classmethod
    def decode(cls, body: bytes) -> Program:
        """A SET_REFERENCE body as a Program; DeviceError when it does not decode.

        Args:
            body: the message's body (`encode`).

        Returns:
            The program it carries.
        """
        if len(body) < 2:
            raise DeviceError("SET_REFERENCE without its shape and count")
        shape, count = struct.unpack_from("<BB", body)
        if len(body) != 2 + 4 * count:
            raise DeviceError(f"SET_REFERENCE says {count} numbers, holds {(len(body) - 2) / 4}")
        try:
            return cls(Shape(shape), tuple(unpack_floats(body, count, 2).tolist()))
        except (ValueError, ConfigError) as exc:
            raise DeviceError(f"SET_REFERENCE: {exc}") from None


def steps(levels: list[float] | tuple[float, ...], hold: float) -> Program:
    """Levels held `hold` each, in order (the last one to the end of the run).

    Args:
        levels: the reference's levels, in the unit of the rig's reference.
        hold: how long each level is held [s].

    Returns:
        A steps program.
    """
    return Program(Shape.STEPS, (float(hold), *map(float, levels)))
