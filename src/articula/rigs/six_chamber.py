"""The six-chamber actuator rig of chapter 3: the device's program (for the emulator).

The device sequences its 3/3 valves: it fills the commanded side to its pressure, holds it,
vents it at the hold time, and pulses the opposite chambers by the damping policy (δ, start,
length; Eq. 3.4), with millisecond timing. Its sensor is the orientation sensor glued to the
top surface (modelled: its roll, pitch and yaw read over the sensor's serial line at its rate,
turned into the bending vector); telemetry per sensor sample: bend_x, bend_y [deg].
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from articula.control.damping import DampingPolicy
from articula.errors import ConfigError, DeviceError
from articula.loops.six_chamber import deactuate, valve_program
from articula.plants.orientation_sensor import OrientationSensorParams, euler_from_bend
from articula.plants.six_chamber import SixChamberParams
from articula.plants.six_chamber_sim import FILL, HOLD, VENT, Stepper, fill_time
from articula.rigs.emulator import PlayedRun
from articula.rigs.firmware import Inputs, Pins
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import PROTOCOL_VERSION, Channel, Info, Kind, RigKind

FIRMWARE = (0, 2, 0)
CHANNELS = (Channel("bend_x", "deg"), Channel("bend_y", "deg"))
STEP = 1e-4  # [s] the plant's integration step (chapter 3's default)
RECORD_EVERY = 10  # plant steps per kept sample (1 ms)


def encode_damping(policy: DampingPolicy) -> bytes:
    """SET_DAMPING's body: δ, start [s], length [s] as float32.

    Args:
        policy: the damping pulse of Eq. (3.4) to send.

    Returns:
        The message's body, 12 bytes.
    """
    return struct.pack("<fff", policy.delta, policy.start, policy.length)


class SixChamberDevice(PlayedRun):
    """The rig's program, run by the emulator against the simulated actuator and sensor.

    Args:
        actuator: the simulated six-chamber actuator; None: the defaults.
        sensor: the simulated orientation sensor (its rate sets the sample period); None: the
            defaults.
    """

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
        deactuate(
            self.actuator,
            self.sensor,
            program,
            0.0,
            0.01,
            0.01,
            STEP,
            RECORD_EVERY,
            np.random.default_rng(0),
        )

    def configure(self, kind: int, body: bytes) -> None:
        """Take SET_REFERENCE (an actuation program) or SET_DAMPING.

        Args:
            kind: the command's message type.
            body: the command's body.
        """
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

    def setting(self, kind: int) -> bytes:
        """SET_REFERENCE's (the actuation) or SET_DAMPING's body as the device holds it.

        Args:
            kind: the SET_ command's message type.

        Returns:
            The body that command would carry.
        """
        if kind == Kind.SET_REFERENCE:
            return self.actuation.encode()
        if kind == Kind.SET_DAMPING:
            return encode_damping(self.damping)
        raise DeviceError("this rig has no such setting")

    def start(self, duration: float, seed: int) -> None:
        """Fill, hold, vent and damp over `duration`; the sensor's noise from seed. The
        plant runs at the first sample (PlayedRun); the stream is the sensor's samples.

        Args:
            duration: the run's length [s]; it must end after the vent.
            seed: the run's noise seed.
        """
        side, gauge, hold = self.actuation.values
        if not hold < duration:
            raise DeviceError(f"the run ({duration:g} s) ends before the vent ({hold:g} s)")
        if not 0.0 < gauge <= self.actuator.supply:
            raise DeviceError(f"pressure {gauge:g} Pa is outside (0, {self.actuator.supply:g}]")

        def run() -> np.ndarray:
            program = valve_program(self.actuator, side, gauge, hold, self.damping)
            done = deactuate(
                self.actuator,
                self.sensor,
                program,
                side,
                hold,
                duration - hold,
                STEP,
                RECORD_EVERY,
                np.random.default_rng(seed),
            )
            return np.degrees(done.sensor_bend)  # (bend_x, bend_y) [deg] per sensor sample

        self._begin(run)


FILL_STEPS = 95  # the fill table's rows: 0.00, 0.01, ..., 0.95 of the supply


def fill_table(params: SixChamberParams) -> np.ndarray:
    """Valve open times that fill a still chamber to 0, 1, ..., 95 % of the supply: the
    firmware's calibration of Eq. (3.4)'s pulse (firmware/src/fill_table.h).

    Args:
        params: the actuator (its supply pressure and valves).

    Returns:
        The open time to k % of the supply for k = 0..95, shape (96,) [s].
    """
    return np.array([fill_time(params, k / 100 * params.supply) for k in range(FILL_STEPS + 1)])


def _table_rows(params: SixChamberParams) -> list[str]:
    """The fill table's values as the header writes them (9 significant digits)."""
    return [f"{t:.9e}" for t in fill_table(params)]


def fill_table_bytes(params: SixChamberParams) -> bytes:
    """The fill table as the firmware holds it: float32, little-endian, each the value the
    compiler reads from the header's decimal.

    Args:
        params: the actuator the table is computed for.

    Returns:
        The table's bytes, (FILL_STEPS + 1) · 4.
    """
    return np.array([float(v) for v in _table_rows(params)], dtype="<f4").tobytes()


def fill_table_header(params: SixChamberParams, source: str = "SixChamberParams defaults") -> str:
    """firmware/src/fill_table.h for `params` (tools/fill_table.py writes it).

    Args:
        params: the actuator the table is computed for.
        source: where its constants came from, for the header's comment.

    Returns:
        The header's C source.
    """
    rows = ",\n".join(f"    {v}f" for v in _table_rows(params))
    return f"""/* Generated by tools/fill_table.py from articula's six-chamber model
 * ({source}, supply {params.supply:g} Pa): the valve open time [s] that
 * fills a still chamber from 0 to k % of the supply, k = 0..{FILL_STEPS}. A real rig
 * measures these instead. */
#ifndef ARTICULA_FILL_TABLE_H
#define ARTICULA_FILL_TABLE_H

#include <avr/pgmspace.h>

#define SUPPLY_PA {params.supply:.9e}f
#define FILL_STEPS {FILL_STEPS}

static const float fill_seconds[FILL_STEPS + 1] PROGMEM = {{
{rows}}};

#endif
"""


SENSOR_FRAME = b"\xa5\x5a"  # then roll, pitch, yaw float32 [deg] and their bytes' sum
# The firmware's valve coils (firmware/src/six_chamber.c): chamber i's (port, fill bit, vent
# bit); D22-D29 are PA0-PA7, D30-D33 are PC7-PC4.
COILS = (
    ("porta", 0, 1),
    ("porta", 2, 3),
    ("porta", 4, 5),
    ("porta", 6, 7),
    ("portc", 7, 6),
    ("portc", 5, 4),
)


class SixChamberPins:
    """The six-chamber actuator behind the firmware's pins (rigs/firmware.py): every 0.1 ms
    (the simulation's step) the valve coils' pins set each chamber's valve (fill, vent or
    neither: hold) and the model advances a step; every 10 ms the orientation sensor sends
    its frame on Serial1, its noise drawn from the run's seed as SixChamberDevice draws it.
    The firmware is built for the default actuator (its fill table) and a 100 Hz sensor.

    Args:
        actuator: the simulated actuator; None: the default.
        sensor: the simulated orientation sensor, at 100 Hz; None: the default.
        firmware: the firmware ELF that will run on it, checked to hold the actuator's fill
            table (built with `make -C firmware FILL_TABLE=...` for another than the
            default's); None: not checked.
    """

    tick_us = round(STEP * 1e6)
    program = "six_chamber"  # firmware/src/six_chamber.c

    def __init__(
        self,
        actuator: SixChamberParams | None = None,
        sensor: OrientationSensorParams | None = None,
        firmware: Path | None = None,
    ) -> None:
        self.actuator = actuator or SixChamberParams()
        self.sensor = sensor or OrientationSensorParams()
        # A missing or foreign file is left to rigs/elf.py's check, which names the fix.
        built = firmware.read_bytes() if firmware is not None and firmware.is_file() else None
        if built is not None and fill_table_bytes(self.actuator) not in built:
            raise ConfigError(
                "actuator",
                f"{firmware.name}'s fill table (fill_table.h) is not this actuator's; write "
                "its own with `python tools/fill_table.py --plant PLANT --out fill.h` and "
                "build with `make -C firmware FILL_TABLE=fill.h`",
            )
        if self.sensor.rate != 100.0:
            raise ConfigError(
                "sensor.rate", f"the firmware reads a 100 Hz sensor (got {self.sensor.rate:g} Hz)"
            )
        # The model's compiled code loads (or compiles) now, not while the firmware waits.
        self.start(0)
        self.period(Pins(255, 0, 0, 0, 0, 0, 0, 0, 0))
        self.start(0)

    def start(self, seed: int) -> None:
        """A run from rest; the sensor's noise from default_rng(seed), three draws a frame.

        Args:
            seed: the run's noise seed.
        """
        self._plant = Stepper(self.actuator, STEP)
        self._rng = np.random.default_rng(seed)
        self._n = 0

    def period(self, pins: Pins) -> Inputs:
        """A sensor frame when one is due (state at the step's start), then a step with the
        valves the pins set.

        Args:
            pins: the firmware's outputs now (the valve coils on PORTA and PORTC).

        Returns:
            The sensor's frame on Serial1 when one is due (else no bytes).
        """
        frame = b""
        if self._n % round(1 / (self.sensor.rate * STEP)) == 0:
            euler = euler_from_bend(self._plant.beta)[0]
            if not self.sensor.ideal:
                euler = euler + np.radians(self.sensor.noise_deg) * self._rng.standard_normal(3)
            data = np.degrees(euler).astype("<f4").tobytes()
            frame = SENSOR_FRAME + data + bytes([sum(data) & 0xFF])
        self._plant.advance(np.array([_valve(pins, coils) for coils in COILS]))
        self._n += 1
        return Inputs(serial1=frame)


def _valve(pins: Pins, coils: tuple[str, int, int]) -> int:
    """A chamber's valve position from its two coils' pins (both on: the spool centres)."""
    port, fill, vent = coils
    bits = getattr(pins, port)
    on_fill, on_vent = bits >> fill & 1, bits >> vent & 1
    return FILL if on_fill and not on_vent else VENT if on_vent and not on_fill else HOLD
