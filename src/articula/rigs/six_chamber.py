"""The six-chamber actuator rig of chapter 3: the device's program (for the emulator).

The device sequences its 3/3 valves: it fills the commanded side to its pressure, holds it,
vents it at the hold time, and pulses the opposite chambers by the damping policy (δ, start,
length; Eq. 3.4), with millisecond timing. Its sensor is the orientation sensor glued to the
top surface (modelled: its roll, pitch and yaw read over the sensor's serial line at its rate,
turned into the bending vector); telemetry per sensor sample: bend_x, bend_y [deg].
"""

from __future__ import annotations

import struct

import numpy as np

from articula.control.damping import DampingPolicy
from articula.errors import ConfigError, DeviceError
from articula.loops.six_chamber import deactuate, valve_program
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import SixChamberParams
from articula.rigs.emulator import PlayedRun
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import PROTOCOL_VERSION, Channel, Info, Kind, RigKind

FIRMWARE = (0, 1, 0)
CHANNELS = (Channel("bend_x", "deg"), Channel("bend_y", "deg"))
STEP = 1e-4  # [s] the plant's integration step (chapter 3's default)
RECORD_EVERY = 10  # plant steps per kept sample (1 ms)


def encode_damping(policy: DampingPolicy) -> bytes:
    """SET_DAMPING's body: δ, start [s], length [s] as float32."""
    return struct.pack("<fff", policy.delta, policy.start, policy.length)


class SixChamberDevice(PlayedRun):
    """The rig's program, run by the emulator against the simulated actuator and sensor."""

    def __init__(
        self,
        actuator: SixChamberParams | None = None,
        sensor: OrientationSensorParams | None = None,
    ) -> None:
        self.actuator = actuator or SixChamberParams()
        self.sensor = sensor or OrientationSensorParams()
        period_us = round(1e6 / self.sensor.rate)
        self.info = Info(RigKind.SIX_CHAMBER, PROTOCOL_VERSION, FIRMWARE, period_us, CHANNELS)
        self.actuation = Program(Shape.ACTUATION, (0.0, self.actuator.supply, 1.0))
        self.damping = DampingPolicy()
        # The plant's compiled code loads (or compiles) now, not while a host waits on a run.
        program = valve_program(self.actuator, 0.0, 1.0, 0.01, self.damping)
        deactuate(self.actuator, self.sensor, program, 0.0, 0.01, 0.01, STEP, RECORD_EVERY,
                  np.random.default_rng(0))  # fmt: skip

    def configure(self, kind: int, body: bytes) -> None:
        """Take SET_REFERENCE (an actuation program) or SET_DAMPING."""
        try:
            if kind == Kind.SET_REFERENCE:
                program = Program.decode(body)
                if program.shape != Shape.ACTUATION:
                    raise DeviceError("the six-chamber rig runs an actuation program")
                self.actuation = program
            elif kind == Kind.SET_DAMPING:
                delta, start, length = struct.unpack("<fff", body)
                self.damping = DampingPolicy(delta=delta, start=start, length=length)
            else:
                raise DeviceError(f"the six-chamber rig does not take {Kind(kind).name}")
        except (ConfigError, ValueError) as exc:
            raise DeviceError(f"{Kind(kind).name}: {exc}") from None

    def start(self, duration: float, seed: int) -> None:
        """Fill, hold, vent and damp over `duration` [s]; the sensor's noise from seed. The
        plant runs at the first sample (PlayedRun); the stream is the sensor's samples."""
        side, gauge, hold = self.actuation.values
        if not hold < duration:
            raise DeviceError(f"the run ({duration:g} s) ends before the vent ({hold:g} s)")
        if not 0.0 < gauge <= self.actuator.supply:
            raise DeviceError(f"pressure {gauge:g} Pa is outside (0, {self.actuator.supply:g}]")

        def run() -> np.ndarray:
            program = valve_program(self.actuator, side, gauge, hold, self.damping)
            done = deactuate(self.actuator, self.sensor, program, side, hold, duration - hold,
                             STEP, RECORD_EVERY, np.random.default_rng(seed))  # fmt: skip
            return np.degrees(done.sensor_bend)  # (bend_x, bend_y) [deg] per sensor sample

        self._begin(run)
