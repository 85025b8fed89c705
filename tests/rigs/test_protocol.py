"""rigs/protocol.py: COBS against its published examples, CRC-16 against its check value,
frames that survive the round trip and damaged ones that never pass, resynchronisation."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from articula.errors import DeviceError
from articula.rigs.protocol import (
    MAX_FRAME,
    Channel,
    Deframer,
    Info,
    Kind,
    RigKind,
    cobs_decode,
    cobs_encode,
    crc16,
    decode,
    decode_info,
    encode,
    encode_info,
    pack_floats,
    unpack_floats,
)


def test_crc16_ccitt_false_check_value():
    assert crc16(b"123456789") == 0x29B1  # the catalogue's check value of CRC-16/CCITT-FALSE


def bitwise_crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE bit by bit, as the firmware computes it."""
    crc = 0xFFFF
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


@given(st.binary(max_size=300))
def test_crc16_is_the_bitwise_crc(data):
    assert crc16(data) == bitwise_crc16(data)


@pytest.mark.parametrize(
    ("raw", "stuffed"),
    [
        (b"\x00", b"\x01\x01"),
        (b"\x00\x00", b"\x01\x01\x01"),
        (b"\x11\x22\x00\x33", b"\x03\x11\x22\x02\x33"),
        (b"\x11\x22\x33\x44", b"\x05\x11\x22\x33\x44"),
        (b"\x11\x00\x00\x00", b"\x02\x11\x01\x01\x01"),
        (bytes(range(1, 255)), b"\xff" + bytes(range(1, 255))),
    ],
)
def test_cobs_published_examples(raw, stuffed):
    assert cobs_encode(raw) == stuffed
    assert cobs_decode(stuffed) == raw


@given(st.binary(max_size=MAX_FRAME))
def test_cobs_round_trip_leaves_no_zero(raw):
    stuffed = cobs_encode(raw)
    assert b"\0" not in stuffed
    assert cobs_decode(stuffed) == raw


@given(st.integers(0, 255), st.integers(0, 0xFFFF), st.binary(max_size=MAX_FRAME - 5))
def test_a_frame_round_trips(kind, seq, body):
    wire = encode(kind, seq, body)
    assert wire.count(b"\0") == 1 and wire.endswith(b"\0")
    frame = decode(wire[:-1])
    assert (frame.kind, frame.seq, frame.body) == (kind, seq, body)


def test_every_single_bit_error_is_caught():
    wire = encode(Kind.TELEMETRY, 513, pack_floats([1.5, -2.25, 3e-3]) + b"\x00\x07")[:-1]
    for i in range(len(wire)):
        for bit in range(8):
            damaged = bytearray(wire)
            damaged[i] ^= 1 << bit
            with pytest.raises(DeviceError):
                decode(bytes(damaged))


def test_a_frame_too_long_is_refused():
    with pytest.raises(DeviceError, match="exceeds"):
        encode(Kind.TELEMETRY, 0, bytes(MAX_FRAME))


def test_the_deframer_resynchronises_after_garbage_and_split_reads():
    frames = [encode(Kind.ACK, k, bytes([k, 0, k])) for k in range(5)]
    stream = b"\x13\x37garbage" + frames[0] + frames[1][:3] + b"" + frames[1][3:] + frames[2]
    stream += frames[3][:-4] + frames[4]  # frame 3 cut short: it merges with 4 and fails
    deframer = Deframer()
    got = []
    for start in range(0, len(stream), 7):  # reads of 7 bytes
        for raw in deframer.feed(stream[start : start + 7]):
            try:
                got.append(decode(raw).seq)
            except DeviceError:
                got.append(None)
    # The garbage runs into frame 0 (no delimiter between them) and frame 3 into frame 4:
    # each pair fails its check once, and the next frame decodes.
    assert got == [None, 1, 2, None]


def test_the_handshake_round_trips():
    info = Info(RigKind.MOTOR, 1, (0, 3, 1), 1000,
                (Channel("current", "A"), Channel("pwm", "counts")))  # fmt: skip
    assert decode_info(encode_info(info)) == info
    with pytest.raises(DeviceError, match="handshake"):
        decode_info(encode_info(info)[:-3])


def test_reals_travel_as_float32():
    assert unpack_floats(pack_floats([0.1, 2.0]), 2).tolist() == [
        pytest.approx(0.1, rel=1e-7), 2.0]  # fmt: skip
    with pytest.raises(DeviceError, match="expected 3 reals"):
        unpack_floats(pack_floats([1.0, 2.0]), 3)
