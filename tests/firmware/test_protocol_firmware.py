"""The firmware's side of docs/protocol.md (C, firmware/src) on a simulated ATmega2560 in
simavr, through its UART behind a pty and pyserial, against the Python side."""

from __future__ import annotations

import re
import struct
import time
from pathlib import Path

import pytest
import serial

from articula.errors import DeviceError
from articula.rigs import protocol
from articula.rigs.link import Link, Status
from articula.rigs.motor import FIRMWARE, MEASURED, MotorGains
from articula.rigs.pneunet import PneuNetDevice
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import MAX_FRAME, PROTOCOL_VERSION, Info, Kind, RigKind, RunEnd
from articula.rigs.run import run_program

pytestmark = pytest.mark.firmware
SOURCES = Path(__file__).resolve().parents[2] / "firmware" / "src"
LITERAL = r'"((?:[^"\\]|\\.)*)"'


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


def wait_for_samples(link: Link) -> Status:
    """STATUS until the run has samples (each STATUS keeps the host timeout at bay)."""
    for _ in range(10_000):
        status = link.status()
        if status.samples:
            return status
    raise AssertionError("the run took no sample")


def test_a_run_reports_its_samples_refuses_settings_and_stops_on_stop(simavr):
    with Link(simavr("motor")) as link:  # no plant: the ADC reads 0 V, the loop still runs
        link.command(Kind.START, struct.pack("<fIH", 60.0, 0, 60_000))
        status = wait_for_samples(link)
        assert status.running and status.ended == RunEnd.NOT_ENDED
        with pytest.raises(DeviceError, match=r"at rest.*code 4"):
            link.command(Kind.SET_GAINS, MotorGains().encode())
        with pytest.raises(DeviceError, match=r"STOP it first.*code 4"):
            link.command(Kind.START, struct.pack("<fI", 1.0, 0))
        link.command(Kind.STOP)
        status = link.status()
        assert not status.running and status.ended == RunEnd.STOP
        t, rows = run_program(link, 0.05, 0)  # the next run is whole, from sample 0
        assert len(t) == 50 and t[0] == 0.0 and rows.shape == (50, len(MEASURED))
        assert link.status() == Status(False, 50, 0, RunEnd.DONE)  # and no byte was lost


def test_start_refuses_a_host_timeout_out_of_range(simavr):
    with Link(simavr("pneunet")) as link:
        for timeout in (0, 19, 60_001):
            with pytest.raises(DeviceError, match=r"host_timeout_ms must be 20-60000.*code 3"):
                link.command(Kind.START, struct.pack("<fIH", 1.0, 0, timeout))
        assert not link.status().running


def test_damaged_and_overlong_frames_are_dropped_and_the_next_one_answered(simavr):
    port = serial.serial_for_url(simavr("pneunet"), baudrate=1_000_000, timeout=0.5)
    hello = protocol.encode(Kind.HELLO, 7)
    damaged = bytearray(hello)
    damaged[2] ^= 0x10  # the CRC no longer matches
    # Neither the damaged frame nor the junk past a frame's length is answered: the first
    # answer that comes is the HELLO's (the firmware takes its bytes in order).
    port.write(bytes(damaged) + bytes(range(1, 256)) * 3 + b"\0" + hello)
    deframer = protocol.Deframer()
    frames = []
    deadline = time.monotonic() + 5
    while not frames and time.monotonic() < deadline:
        frames = deframer.feed(port.read(64))
    frame = protocol.decode(frames[0])
    assert frame.kind == Kind.INFO and frame.seq == 1  # the first after its start-up INFO
    port.close()


def error_text_cap() -> int:
    """The longest ERROR text send_error (firmware/src/protocol.c) sends whole: the size of
    the body it builds (reply_body), with protocol.h's constants, less the seq and the code."""
    defines = dict(re.findall(r"#define (\w+) (\d+)", (SOURCES / "protocol.h").read_text()))
    code = (SOURCES / "protocol.c").read_text()
    function = code.split("void send_error(", 1)[1].split("\n}", 1)[0]
    assert "reply_body" in function and "sizeof reply_body" in function
    size = re.search(r"^uint8_t reply_body\[([^]]+)\];", code, re.M).group(1)
    size = re.sub(r"[A-Z_]+", lambda name: defines[name.group(0)], size)
    assert re.fullmatch(r"[\d\s()+*/-]+", size), size
    return eval(size) - 3  # a seq (u16) and a code (u8) come first


def error_texts() -> list[str]:
    """Every text the firmware's ERRORs carry: send_error's and end_run's literals, the
    settings' and starts' reasons (*why) and the control steps' (returned), from the C
    sources."""
    texts = []
    for source in sorted(SOURCES.glob("*.c")):
        code = source.read_text()
        for call in re.findall(r"(?<!void )\b(?:send_error|end_run)\(([^;]*)\);", code):
            if call.rsplit(",", 1)[-1].strip() in ("why", "reason", "0"):
                continue  # a hook's reason (its *why or return, below), or an end without one
            assert re.search(LITERAL, call), f"{source.name}: send_error({call}) without a text"
            texts.append("".join(re.findall(LITERAL, call)))
        for reason in re.findall(r"\*why\s*=\s*([^;]*);", code):
            assert re.fullmatch(rf"(\s*{LITERAL})+\s*", reason), f"{source.name}: {reason}"
            texts.append("".join(re.findall(LITERAL, reason)))
        for reason in re.finditer(rf"\breturn\s+({LITERAL});", code):  # a control step's end
            texts.append("".join(re.findall(LITERAL, reason.group(1))))
    return [text for text in texts if text]  # not rig.c's empty default reason


def test_every_error_text_of_the_firmware_goes_out_whole():
    cap = error_text_cap()
    assert cap <= MAX_FRAME - 5 - 3  # an ERROR's text within a frame (docs/protocol.md)
    texts = error_texts()
    assert len(texts) >= 15 and "the run ends before the vent" in texts
    assert [text for text in texts if len(text) > cap] == []
    assert all(text.isascii() and text.isprintable() for text in texts)


def test_the_longest_refusals_arrive_whole(simavr):
    side = "this firmware fills a chamber's side (a multiple of 60 deg) at the supply"
    order = "SET_GAINS: gains must be >= 0 and the filter order 1-100 on this firmware"
    with Link(simavr("six_chamber")) as link, pytest.raises(DeviceError) as refused:
        link.command(Kind.SET_REFERENCE, Program(Shape.ACTUATION, (30.0, 60e3, 1.0)).encode())
    assert str(refused.value).endswith(f": the rig refused: {side} (code 3)")
    with Link(simavr("motor")) as link, pytest.raises(DeviceError) as refused:
        link.command(Kind.SET_GAINS, MotorGains(filter_order=101).encode())
    assert str(refused.value).endswith(f": the rig refused: {order} (code 3)")
