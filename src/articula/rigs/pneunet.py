"""The PneuNet rig of chapter 2: the device's program (for the emulator) and the host driver.

The controller runs on the device, as on the book's Arduino: each PWM period it reads the flex
sensor, evaluates the PID of the gains it was sent (Eqs. 2.2-2.4) against its reference
program and writes the valve's 8-bit PWM count. Telemetry per sample: the reference [°], the
sensor's angle [°] and the PWM count. The host sends gains, a reference program, and START
with the run's length and the noise seed (an emulated rig draws its sensor noise from it; a
real one ignores it).
"""

from __future__ import annotations

import math
import struct

import numpy as np

from articula.control.pid import PID, GainSchedule
from articula.errors import ConfigError, DeviceError
from articula.plants.pneunet import PneuNetBatch, PneuNetParams
from articula.rigs.firmware import Inputs, Pins
from articula.rigs.link import Link
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import (
    PROTOCOL_VERSION,
    Channel,
    Info,
    Kind,
    RigKind,
    pack_floats,
    unpack_floats,
)
from articula.rigs.run import run_program
from articula.tuning.response import Response

FIRMWARE = (0, 2, 0)
CHANNELS = (Channel("reference", "deg"), Channel("angle", "deg"), Channel("pwm", "counts"))
SCHEDULES = ("constant", "piecewise", "fuzzy")


def encode_gains(schedule: GainSchedule) -> bytes:
    """SET_GAINS' body: schedule u8, rows u8, then per row K_p, K_i, K_d and its point (float32).

    Args:
        schedule: the PID gains K(θ_r) of Eq. (2.4) to send.

    Returns:
        The message's body, 2 + 16 · rows bytes.
    """
    rows = schedule.gains.shape[0]
    points = np.broadcast_to(schedule.points, (rows,))
    table = np.column_stack([schedule.gains, points])
    return struct.pack("<BB", SCHEDULES.index(schedule.kind), rows) + pack_floats(table.ravel())


def decode_gains(body: bytes) -> GainSchedule:
    """SET_GAINS' body as a GainSchedule; DeviceError when it does not decode.

    Args:
        body: the message's body (`encode_gains`).

    Returns:
        The gain schedule it carries.
    """
    if len(body) < 2 or body[0] >= len(SCHEDULES) or len(body) != 2 + 16 * body[1]:
        raise DeviceError("SET_GAINS does not decode")
    table = unpack_floats(body, 4 * body[1], 2).reshape(body[1], 4)
    try:
        return GainSchedule(SCHEDULES[body[0]], table[:, :3], table[:, 3])
    except ConfigError as exc:
        raise DeviceError(f"SET_GAINS: {exc}") from None


class PneuNetDevice:
    """The rig's program, run by the emulator against the simulated actuator.

    Args:
        params: the simulated PneuNet and its flex sensor; None: the defaults.
    """

    def __init__(self, params: PneuNetParams | None = None) -> None:
        self.params = params or PneuNetParams()
        period_us = round(self.params.pwm_period * 1e6)
        self.info = Info(RigKind.PNEUNET, PROTOCOL_VERSION, FIRMWARE, period_us, CHANNELS)
        self.schedule = GainSchedule("constant", np.array([[1.0, 1.0, 0.0]]))
        self.program = Program(Shape.CONSTANT, (0.0,))
        self.output: float | None = None  # a PWM count held open-loop (SET_OUTPUT)
        self._steps = 0

    def configure(self, kind: int, body: bytes) -> None:
        """Take SET_GAINS, SET_REFERENCE or SET_OUTPUT (channel 0: the PWM count).

        Args:
            kind: the command's message type.
            body: the command's body.
        """
        if kind == Kind.SET_GAINS:
            self.schedule = decode_gains(body)
        elif kind == Kind.SET_REFERENCE:
            self.program = Program.decode(body)
        elif kind == Kind.SET_OUTPUT:
            channel, value = struct.unpack("<Bf", body)
            if channel != 0 or not 0.0 <= value <= 255.0:
                raise DeviceError("SET_OUTPUT: channel 0 takes a PWM count in 0-255")
            self.output = value
        else:
            raise DeviceError(f"the PneuNet rig does not take {Kind(kind).name}")

    def setting(self, kind: int) -> bytes:
        """SET_GAINS', SET_REFERENCE's or SET_OUTPUT's body as the device holds it (the
        output -1 when there is none).

        Args:
            kind: the SET_ command's message type.

        Returns:
            The body that command would carry.
        """
        if kind == Kind.SET_GAINS:
            return encode_gains(self.schedule)
        if kind == Kind.SET_REFERENCE:
            return self.program.encode()
        if kind == Kind.SET_OUTPUT:
            return struct.pack("<Bf", 0, -1.0 if self.output is None else self.output)
        raise DeviceError("this rig has no such setting")

    def start(self, duration: float, seed: int) -> None:
        """A run of `duration` from rest; sensor noise from seed as run_closed_loop draws
        it (the first of SeedSequence(seed)'s two streams).

        Args:
            duration: the run's length [s].
            seed: the run's noise seed.
        """
        self._steps = round(duration / self.params.pwm_period)
        noise_seed, _ = np.random.SeedSequence(seed).spawn(2)
        self._noise = np.random.default_rng(noise_seed).standard_normal(self._steps)
        self._plant = PneuNetBatch(self.params, 1, None)
        self._pid = PID(self.schedule, (0.0, 255.0))
        self._pid.reset(1)
        self._n = 0

    def sample(self) -> np.ndarray | None:
        """One PWM period: (reference, angle, PWM count); None when the run is over.

        Returns:
            (reference [deg], measured angle [deg], PWM count), shape (3,); None when the run
            is over.
        """
        if self._n >= self._steps:
            self.output = None  # an open-loop output holds for one run, as on the firmware
            return None
        t = self._n * self.params.pwm_period
        measured = np.degrees(self._plant.read(self._noise[self._n : self._n + 1]))
        reference = float(self.program.at(t))
        if self.output is None:
            count = math.floor(float(self._pid(t, reference, measured)[0]))
        else:
            count = math.floor(self.output)
        self._plant.advance(np.array([count / 255.0]))
        self._n += 1
        return np.array([reference, measured[0], count])

    def stop(self) -> None:
        """End the run: the valve closed."""
        self._steps = self._n
        self.output = None


class PneuNetRig:
    """The tuner's view of a PneuNet rig: run one experiment with gains K over the line and
    return its response, as loops.pneunet_pid.SimulatedRig does in process.

    Args:
        link: the line to a PneuNet rig.
        program: the reference program of every experiment.
        duration: each experiment's length [s].
        seed: the noise seed of the first experiment (the n-th takes seed + n).
    """

    def __init__(self, link: Link, program: Program, duration: float, seed: int) -> None:
        if link.info.rig != RigKind.PNEUNET:
            raise DeviceError(f"{link.port}: a {link.info.rig.name.lower()} rig, not a PneuNet")
        self.link, self.program, self.duration, self.seed = link, program, duration, seed
        self.calls = 0

    def __call__(self, gains: np.ndarray) -> Response:
        """One experiment from rest with constant gains [K_p, K_i, K_d].

        Args:
            gains: [K_p, K_i, K_d], shape (3,) (per degree, as chapter 2's gains).

        Returns:
            The sample times [s], reference [deg] and measured angle [deg] of the run.
        """
        schedule = GainSchedule("constant", np.asarray(gains, dtype=float)[None, :])
        self.link.command(Kind.SET_GAINS, encode_gains(schedule))
        self.link.command(Kind.SET_REFERENCE, self.program.encode())
        t, values = run_program(self.link, self.duration, self.seed + self.calls)
        self.calls += 1
        return Response(t, values[:, 0], values[:, 1])


# The firmware's valve and pump (firmware/src/pneunet.c): Timer1's PWM on D11 with 8333 ticks
# a period, the pump on D8 (PH5). What it is built for: PneuNetParams' defaults below.
VALVE_TICKS = 8333
PUMP_BIT = 5
FIRMWARE_BUILD = ("pwm_period", "sensor_zero", "sensor_gain", "adc_bits", "adc_vref")


class PneuNetPins:
    """The PneuNet's plant behind the firmware's pins (rigs/firmware.py): each PWM period the
    valve's duty (OCR1A of Timer1's period, the pump on) drives the actuator model, and the
    flex sensor is read as the 10-bit ADC's code, its noise drawn from the run's seed as
    PneuNetDevice draws it.

    Args:
        params: the simulated PneuNet; None: the defaults (the ones the firmware is built for).
    """

    tick_us = None  # a PWM period per ADC conversion
    program = "pneunet"  # firmware/src/pneunet.c

    def __init__(self, params: PneuNetParams | None = None) -> None:
        self.params = params or PneuNetParams()
        built = PneuNetParams()
        for name in FIRMWARE_BUILD:
            if getattr(self.params, name) != getattr(built, name):
                raise ConfigError(
                    f"plant.{name}",
                    f"the PneuNet firmware is built for "
                    f"{getattr(built, name):g}; change the config or "
                    "firmware/src/pneunet.c",
                )
        self.start(0)

    def start(self, seed: int) -> None:
        """A run from rest; the sensor's noise from the first of SeedSequence(seed)'s streams.

        Args:
            seed: the run's noise seed.
        """
        noise_seed, _ = np.random.SeedSequence(seed).spawn(2)
        self._rng = np.random.default_rng(noise_seed)
        self._plant = PneuNetBatch(self.params, 1, None)
        self._n = 0

    def period(self, pins: Pins) -> Inputs:
        """The last period's duty acts; the flex sensor's ADC code now.

        Args:
            pins: the firmware's outputs, held over the period just ended (OCR1A, the pump).

        Returns:
            The flex sensor's ADC code at the new period's start.
        """
        if self._n > 0:
            pump = pins.porth >> PUMP_BIT & 1
            self._plant.advance(np.array([pump * min(pins.ocr1a, VALVE_TICKS) / VALVE_TICKS]))
        self._n += 1
        return Inputs(int(self._plant.read_code(self._rng.standard_normal(1))[0]))
