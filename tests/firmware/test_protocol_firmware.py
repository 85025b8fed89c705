"""The firmware's side of docs/protocol.md (C, firmware/src) on a simulated ATmega2560 in
simavr, through its UART behind a pty and pyserial, against the Python side."""

from __future__ import annotations

import struct
import time

import pytest
import serial

from articula.errors import DeviceError
from articula.rigs import protocol
from articula.rigs.link import Link
from articula.rigs.motor import FIRMWARE, MEASURED, MotorGains
from articula.rigs.pneunet import PneuNetDevice
from articula.rigs.protocol import PROTOCOL_VERSION, Info, Kind, RigKind
from articula.rigs.run import run_program

pytestmark = pytest.mark.firmware


def test_the_handshakes_are_byte_for_byte_the_python_rigs(simavr):
    with Link(simavr("pneunet"), RigKind.PNEUNET) as link:
        assert protocol.encode_info(link.info) == protocol.encode_info(PneuNetDevice().info)
        assert link.stats.crc_errors == link.stats.dropped == 0
    # The motor firmware sends what a rig measures; an emulated rig adds the plant's truth.
    motor = Info(RigKind.MOTOR, PROTOCOL_VERSION, FIRMWARE, 1000, MEASURED)
    with Link(simavr("motor"), RigKind.MOTOR) as link:
        assert protocol.encode_info(link.info) == protocol.encode_info(motor)


def test_commands_a_rig_does_not_take_or_values_out_of_range_are_refused_by_name(simavr):
    with Link(simavr("pneunet")) as link:
        with pytest.raises(DeviceError, match=r"does not take.*code 2"):
            link.command(Kind.SET_DAMPING, struct.pack("<fff", 0.4, 0.0, 0.0))
        with pytest.raises(DeviceError, match=r"0-255.*code 3"):
            link.command(Kind.SET_OUTPUT, struct.pack("<Bf", 0, 300.0))
    with Link(simavr("motor")) as link:
        with pytest.raises(DeviceError, match=r"filter order 1-100.*code 3"):
            link.command(Kind.SET_GAINS, MotorGains(filter_order=101).encode())
        with pytest.raises(DeviceError, match=r"5 reals.*code 1"):
            link.command(Kind.SET_GAINS, b"\0" * 8)


def test_a_run_reports_its_samples_refuses_settings_and_stops_on_stop(simavr):
    with Link(simavr("motor")) as link:  # no plant: the ADC reads 0 V, the loop still runs
        link.command(Kind.START, struct.pack("<fI", 60.0, 0))
        time.sleep(0.3)
        running, samples = link.status()
        assert running and samples > 0
        with pytest.raises(DeviceError, match=r"at rest.*code 4"):
            link.command(Kind.SET_GAINS, MotorGains().encode())
        with pytest.raises(DeviceError, match=r"STOP it first.*code 4"):
            link.command(Kind.START, struct.pack("<fI", 1.0, 0))
        link.command(Kind.STOP)
        running, _ = link.status()
        assert not running
        t, rows = run_program(link, 0.05, 0)  # the next run is whole, from sample 0
        assert len(t) == 50 and t[0] == 0.0 and rows.shape == (50, len(MEASURED))


def test_damaged_and_overlong_frames_are_dropped_and_the_next_one_answered(simavr):
    port = serial.serial_for_url(simavr("pneunet"), baudrate=1_000_000, timeout=0.5)
    hello = protocol.encode(Kind.HELLO, 7)
    damaged = bytearray(hello)
    damaged[2] ^= 0x10  # the CRC no longer matches
    for piece in (bytes(damaged), bytes(range(1, 256)) * 3 + b"\0"):  # junk past a frame
        port.write(piece)
        time.sleep(0.1)
    time.sleep(0.2)
    assert port.read(port.in_waiting or 1) == b""  # neither is answered
    port.write(hello)
    deframer = protocol.Deframer()
    frames = []
    deadline = time.monotonic() + 5
    while not frames and time.monotonic() < deadline:
        frames = deframer.feed(port.read(64))
    frame = protocol.decode(frames[0])
    assert frame.kind == Kind.INFO and frame.seq == 0  # the device's first frame
    port.close()
