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
from articula.plants.motor_rig import I_PRIMARY, OMEGA, THETA
from articula.plants.motor_sensors import CurrentSensorParams, adc_code, encoder_count
from articula.rigs.emulator import PlayedRun
from articula.rigs.firmware import Inputs, Pins
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import PROTOCOL_VERSION, Channel, Info, Kind, RigKind

FIRMWARE = (0, 2, 0)
MEASURED = (
    Channel("i_ref", "A"),
    Channel("i_meas", "A"),
    Channel("i_fb", "A"),
    Channel("omega_meas", "rad/s"),
    Channel("v1", "V"),
    Channel("duty1", "counts"),
    Channel("v2", "V"),
)
EMULATED = (Channel("i", "A"), Channel("omega", "rad/s"))  # the plant's truth: emulator only


@dataclass(frozen=True)
class MotorGains:
    """The device's loop settings: current PI (4.14), moving-average order (4.17), speed PI.

    Attributes:
        kp: the current loop's proportional gain K_p [V/A].
        ki: the current loop's integral gain K_i [V/(A·s)].
        filter_order: samples in the current reading's moving average (4.17).
        kp_speed: the load motor's speed-loop proportional gain [V·s/rad].
        ki_speed: the load motor's speed-loop integral gain [V/rad].
    """

    kp: float = 10.0
    ki: float = 100.0
    filter_order: int = 1
    kp_speed: float = 5.0
    ki_speed: float = 10.0

    def encode(self) -> bytes:
        """SET_GAINS' body for the motor rig.

        Returns:
            kp, ki, filter_order, kp_speed, ki_speed as five float32 (20 bytes).
        """
        return struct.pack("<5f", self.kp, self.ki, self.filter_order, self.kp_speed, self.ki_speed)

    @classmethod
    def decode(cls, body: bytes) -> MotorGains:
        """SET_GAINS' body; DeviceError when it does not decode or is out of range.

        Args:
            body: the message's body: five float32 (`encode`).

        Returns:
            The gains it carries.
        """
        if len(body) != 20:
            raise DeviceError(f"SET_GAINS for the motor rig takes 5 reals (got {len(body)} bytes)")
        kp, ki, order, kp_speed, ki_speed = struct.unpack("<5f", body)
        if min(kp, ki, kp_speed, ki_speed) < 0 or not 1 <= order <= 10_000 or order % 1:
            raise DeviceError("SET_GAINS: gains must be >= 0 and the filter order 1-10000")
        return cls(kp, ki, int(order), kp_speed, ki_speed)


# The plant behind an emulated rig: (gains, reference program, duration [s], seed) -> the
# channels of MEASURED + EMULATED, one row per control period (experiments/motor_on_rig.py
# makes one).
Plant = Callable[[MotorGains, Program, float, int], np.ndarray]


class MotorDevice(PlayedRun):
    """The rig's program, run by the emulator against a simulated dual-motor rig.

    Args:
        plant: the simulated rig: (gains, reference program, duration [s], seed) -> one row
            per control period of the MEASURED + EMULATED channels (`Plant`).
        dt: the control period, the rig's sample period [s].
    """

    def __init__(self, plant: Plant, dt: float) -> None:
        self.plant = plant
        channels = MEASURED + EMULATED
        self.info = Info(RigKind.MOTOR, PROTOCOL_VERSION, FIRMWARE, round(dt * 1e6), channels)
        self.gains = MotorGains()
        self.reference = Program(Shape.CURRENT, (1.0, 0.0, 0.0, 5.0))

    def configure(self, kind: int, body: bytes) -> None:
        """Take SET_GAINS (MotorGains) or SET_REFERENCE (a current program).

        Args:
            kind: the command's message type.
            body: the command's body.
        """
        if kind == Kind.SET_GAINS:
            self.gains = MotorGains.decode(body)
        elif kind == Kind.SET_REFERENCE:
            program = Program.decode(body)
            if program.shape != Shape.CURRENT:
                raise DeviceError("the motor rig runs a current program")
            self.reference = program
        else:
            raise DeviceError(f"the motor rig does not take {Kind(kind).name}")

    def setting(self, kind: int) -> bytes:
        """SET_GAINS' or SET_REFERENCE's body as the device holds it.

        Args:
            kind: the SET_ command's message type.

        Returns:
            The body that command would carry.
        """
        if kind == Kind.SET_GAINS:
            return self.gains.encode()
        if kind == Kind.SET_REFERENCE:
            return self.reference.encode()
        raise DeviceError("this rig has no such setting")

    def start(self, duration: float, seed: int) -> None:
        """A run of `duration` from rest; the plant runs at the first sample (PlayedRun).

        Args:
            duration: the run's length [s].
            seed: the seed of the plant's sensor noise.
        """
        if not duration > 0:
            raise DeviceError(f"the run's duration must be > 0 (got {duration:g} s)")
        self._begin(lambda: self.plant(self.gains, self.reference, duration, seed))


# The firmware's H-bridge pins (firmware/src/motor.c): IN1/IN2 on PA2/PA3 for the primary,
# IN3/IN4 on PA4/PA5 for the load motor; forward is the first of each pair high.
DIRECTION_BITS = (2, 4)
NOISE_CHUNK = 4096  # standard normals drawn at a time (the same stream as drawn at once)


class MotorPins:
    """The dual-motor rig's plant behind the firmware's pins (rigs/firmware.py).

    Each control period the duty registers (OCR3A, OCR4A, 8-bit) and the direction pins give
    the voltages the rig model integrates over the period (exact zero-order hold, as
    loops.motor_current does); the ACS712's output is read as the 10-bit ADC's code, with the
    sensor noise drawn from the run's seed as simulate_batch draws it; the encoder's count
    is that of the shaft angle. `trace` keeps the true (i, ω) [A, rad/s] per period.

    Args:
        Ad: the rig's zero-order-hold state matrix over one control period, shape (4, 4)
            (state θ [rad], ω [rad/s], i₁ [A], i₂ [A]; plants.motor_rig).
        Bd: its input matrix, shape (4, 2) (inputs V₁, V₂ [V]).
        sensor: the ACS712 current sensor and the ADC that reads it.
        counts_per_rev: the encoder's counts per shaft revolution.
        v_max: the H-bridges' supply voltage, the voltage at full duty [V].
    """

    tick_us = None  # a control period per ADC conversion
    program = "motor"  # firmware/src/motor.c

    def __init__(
        self,
        Ad: np.ndarray,
        Bd: np.ndarray,
        sensor: CurrentSensorParams,
        counts_per_rev: int,
        v_max: float,
    ) -> None:
        self.Ad, self.Bd, self.sensor = Ad, Bd, sensor
        self.counts_per_rev, self.v_max = counts_per_rev, v_max
        self.trace: list[tuple[float, float]] = []
        # The sensor's compiled code loads (or compiles) now, not while the firmware waits.
        self.start(0)
        self.period(Pins(1, 0, 0, 0, 0, 0, 0, 0, 0))
        self.start(0)

    def start(self, seed: int) -> None:
        """A run from rest; sensor noise from default_rng(seed) in order.

        Args:
            seed: the run's noise seed.
        """
        self.x = np.zeros(self.Ad.shape[0])
        self._rng = np.random.default_rng(seed)
        self._noise = np.empty(0)
        self._n = 0
        self.trace = []

    def period(self, pins: Pins) -> Inputs:
        """The outputs held over the last period act; the ADC code and encoder count now.

        Args:
            pins: the firmware's outputs, held over the period just ended.

        Returns:
            The current sensor's ADC code and the encoder's count at the new period's start.
        """
        if self._n > 0:
            volts = [
                self._voltage(duty, pins.porta, bit)
                for duty, bit in zip((pins.ocr3a, pins.ocr4a), DIRECTION_BITS, strict=True)
            ]
            self.x = self.Ad @ self.x + self.Bd @ np.array(volts)
        if self._n % NOISE_CHUNK == 0:
            self._noise = self._rng.standard_normal(NOISE_CHUNK)
        s = self.sensor
        i, omega, theta = self.x[I_PRIMARY], self.x[OMEGA], self.x[THETA]
        code = adc_code(
            i,
            self._noise[self._n % NOISE_CHUNK],
            s.sensitivity,
            s.zero_voltage,
            s.noise_sigma,
            s.adc_bits,
            s.adc_vref,
        )
        self._n += 1
        self.trace.append((float(i), float(omega)))
        return Inputs(int(code), int(encoder_count(theta, self.counts_per_rev)))

    def _voltage(self, duty: int, porta: int, bit: int) -> float:
        """The H-bridge's mean voltage [V] for a duty count and its direction pins."""
        sign = {1: 1.0, 2: -1.0}.get((porta >> bit) & 3, 0.0)
        return sign * self.v_max * (duty & 0xFF) / 256
