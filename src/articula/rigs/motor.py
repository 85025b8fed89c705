"""The dual-motor rig of chapter 4: the device's program (for the emulator).

The device closes the 1 kHz current loop (ACS712 reading, moving average (4.17), PI +
feed-forward (4.13)-(4.14), PWM (4.15)-(4.16)) and the load motor's speed loop (4.12) on its
own; the host sends the gains (SET_GAINS: K_p, K_i [V/A, V/(A·s)], the filter order, the
speed loop's K_p, K_i) and the reference (a `current` program). Telemetry per control period:
what a rig measures and commands, then, on an emulated rig only, the plant's true current
and speed (`i`, `omega`), which chapter 4's metrics are taken on.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from articula.errors import DeviceError
from articula.rigs.emulator import PlayedRun
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import PROTOCOL_VERSION, Channel, Info, Kind, RigKind

FIRMWARE = (0, 1, 0)
MEASURED = (Channel("i_ref", "A"), Channel("i_meas", "A"), Channel("i_fb", "A"),
            Channel("omega_meas", "rad/s"), Channel("v1", "V"), Channel("duty1", "counts"),
            Channel("v2", "V"))  # fmt: skip
EMULATED = (Channel("i", "A"), Channel("omega", "rad/s"))  # the plant's truth: emulator only


@dataclass(frozen=True)
class MotorGains:
    """The device's loop settings: current PI (4.14), moving-average order (4.17), speed PI."""

    kp: float = 10.0  # [V/A]
    ki: float = 100.0  # [V/(A·s)]
    filter_order: int = 1
    kp_speed: float = 5.0  # [V·s/rad]
    ki_speed: float = 10.0  # [V/rad]

    def encode(self) -> bytes:
        """SET_GAINS' body for the motor rig: five float32."""
        return struct.pack("<5f", self.kp, self.ki, self.filter_order, self.kp_speed,
                           self.ki_speed)  # fmt: skip

    @classmethod
    def decode(cls, body: bytes) -> MotorGains:
        """SET_GAINS' body; DeviceError when it does not decode or is out of range."""
        if len(body) != 20:
            raise DeviceError(f"SET_GAINS for the motor rig takes 5 reals (got {len(body)} bytes)")
        kp, ki, order, kp_speed, ki_speed = struct.unpack("<5f", body)
        if min(kp, ki, kp_speed, ki_speed) < 0 or not 1 <= order <= 10_000 or order % 1:
            raise DeviceError("SET_GAINS: gains must be >= 0 and the filter order 1-10000")
        return cls(kp, ki, int(order), kp_speed, ki_speed)


# The plant behind an emulated rig: (gains, reference program, duration [s], seed) -> the
# channels of MEASURED + EMULATED, one row per control period (book/ch4/rig.py makes one).
Plant = Callable[[MotorGains, Program, float, int], np.ndarray]


class MotorDevice(PlayedRun):
    """The rig's program, run by the emulator against a simulated dual-motor rig."""

    def __init__(self, plant: Plant, dt: float) -> None:
        self.plant = plant
        channels = MEASURED + EMULATED
        self.info = Info(RigKind.MOTOR, PROTOCOL_VERSION, FIRMWARE, round(dt * 1e6), channels)
        self.gains = MotorGains()
        self.reference = Program(Shape.CURRENT, (1.0, 0.0, 0.0, 5.0))

    def configure(self, kind: int, body: bytes) -> None:
        """Take SET_GAINS (MotorGains) or SET_REFERENCE (a current program)."""
        if kind == Kind.SET_GAINS:
            self.gains = MotorGains.decode(body)
        elif kind == Kind.SET_REFERENCE:
            program = Program.decode(body)
            if program.shape != Shape.CURRENT:
                raise DeviceError("the motor rig runs a current program")
            self.reference = program
        else:
            raise DeviceError(f"the motor rig does not take {Kind(kind).name}")

    def start(self, duration: float, seed: int) -> None:
        """A run of `duration` [s] from rest; the plant runs at the first sample (PlayedRun)."""
        if not duration > 0:
            raise DeviceError(f"the run's duration must be > 0 (got {duration:g} s)")
        self._begin(lambda: self.plant(self.gains, self.reference, duration, seed))
