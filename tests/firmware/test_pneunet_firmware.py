"""The PneuNet firmware (C, firmware/src) on a simulated ATmega2560 in simavr, through its
UART behind a pty and pyserial, against the Python side of the protocol."""

from __future__ import annotations

import time

import pytest
import serial

from articula.errors import DeviceError
from articula.rigs import protocol
from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetDevice
from articula.rigs.protocol import Kind, RigKind

pytestmark = pytest.mark.firmware


def test_the_handshake_is_byte_for_byte_the_emulated_rigs(simavr):
    with Link(simavr("pneunet"), RigKind.PNEUNET) as link:
        assert protocol.encode_info(link.info) == protocol.encode_info(PneuNetDevice().info)
        assert link.stats.crc_errors == link.stats.dropped == 0


def test_a_command_the_firmware_lacks_is_refused_by_name(simavr):
    with Link(simavr("pneunet")) as link, pytest.raises(DeviceError, match="code 2"):
        link.command(Kind.STREAM, b"\x01\x00")


def test_damaged_and_overlong_frames_are_dropped_and_the_next_one_answered(simavr):
    port = serial.serial_for_url(simavr("pneunet"), baudrate=1_000_000, timeout=0.5)
    hello = protocol.encode(Kind.HELLO, 7)
    damaged = bytearray(hello)
    damaged[2] ^= 0x10  # the CRC no longer matches
    # Then 510 bytes of junk and a delimiter, in pieces: simavr's pty bridge (uart_pty) holds
    # 512 bytes and stops for good when one write overfills it; the host never sends more
    # than one frame (at most 256 bytes) before its answer.
    for piece in (bytes(damaged), bytes(range(1, 256)), bytes(range(1, 256)) + b"\0"):
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
