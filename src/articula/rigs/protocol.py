"""The rigs' serial protocol (docs/protocol.md): COBS-framed binary messages with a CRC-16.

On the wire a frame is COBS(header + body + CRC) followed by a zero byte. The header is the
message type (one byte) and the sender's sequence number (u16, little-endian, wrapping); the
CRC is CRC-16/CCITT-FALSE of header and body, little-endian. Numbers are little-endian;
reals are IEEE-754 float32, as the ATmega2560's avr-gcc stores them. COBS leaves no zero byte
inside a frame, so a receiver that lost its place resynchronises at the next zero.
"""

from __future__ import annotations

import binascii
import struct
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from articula.errors import DeviceError

PROTOCOL_VERSION = 2
MAX_FRAME = 254  # bytes of header + body + CRC: one COBS block, a zero-free 255-byte frame
MAX_KEPT = 4 * MAX_FRAME  # stuffed bytes of one frame kept to check it; longer: damaged
HEADER = struct.Struct("<BH")  # type, sequence number
CRC = struct.Struct("<H")


class Kind(IntEnum):
    """Message types: host commands below 0x80, device messages from 0x80."""

    HELLO = 0x01  # () -> INFO
    SET_GAINS = 0x02  # schedule, gains rows and breakpoints (encode_gains)
    SET_REFERENCE = 0x03  # a reference program (encode_reference)
    START = 0x04  # duration [s] float32, noise seed u32: a run from rest; DONE at its end
    STOP = 0x05  # () ends a run now (actuators off)
    SET_OUTPUT = 0x06  # channel u8, value float32: one actuator command held until STOP
    SET_DAMPING = 0x07  # delta, start [s], length [s] float32: the chapter-3 policy
    STREAM = 0x08  # decimation u16: one TELEMETRY frame every that many samples (0: none)
    STATUS = 0x09  # () -> ACK: running u8, samples u32, rx_overruns u16, ended u8 after the seq
    GET = 0x0A  # the type of a SET_ command u8 -> ACK: that setting's body after the seq
    INFO = 0x81  # the handshake (encode_info); also sent unasked after a reset
    ACK = 0x82  # acknowledged sequence number u16
    ERROR = 0x83  # sequence number u16, code u8, text (ASCII)
    TELEMETRY = 0x84  # device time [µs] u32, then one float32 per channel of INFO
    DONE = 0x85  # sequence number of the START u16, samples taken u32


class ErrorCode(IntEnum):
    """Codes of ERROR replies."""

    BAD_FRAME = 1  # a command that does not decode (its body has the wrong length)
    UNKNOWN = 2  # a message type this rig does not take
    BAD_VALUE = 3  # a value out of the rig's range
    BUSY = 4  # a command that needs the rig at rest, during a run
    STOPPED = 5  # the device ended the run itself (the host's silence, an error): safe state


class ResetCause(IntEnum):
    """Why a device (re)started, as its INFO says (the ATmega2560's MCUSR)."""

    POWER_ON = 0
    EXTERNAL = 1  # its reset pin: the button, the USB bridge's DTR, the emulator's reset
    WATCHDOG = 2  # its program stopped coming round its main loop
    BROWN_OUT = 3  # its supply dropped


class RunEnd(IntEnum):
    """How the last run ended, as STATUS says."""

    NOT_ENDED = 0  # running, or no run yet
    DONE = 1  # its whole duration
    STOP = 2  # the host's STOP
    HOST_TIMEOUT = 3  # no frame from the host within host_timeout_ms
    ERROR = 4  # the device's own error (a missed period, a silent sensor, the watchdog)


class RigKind(IntEnum):
    """The three rigs of chapters 2-4."""

    PNEUNET = 1
    SIX_CHAMBER = 2
    MOTOR = 3


@dataclass(frozen=True)
class Frame:
    """One decoded message: its type, the sender's sequence number and its body.

    Attributes:
        kind: the message type (a `Kind` value, or an unknown type as received).
        seq: the sender's sequence number (u16, wrapping).
        body: the message's fields (docs/protocol.md), without header and CRC.
    """

    kind: int
    seq: int
    body: bytes


@dataclass(frozen=True)
class Channel:
    """A telemetry channel: name and unit (SI or counts).

    Attributes:
        name: the channel's name (ASCII), e.g. "angle".
        unit: its unit (ASCII), e.g. "deg", "A", "counts".
    """

    name: str
    unit: str


@dataclass(frozen=True)
class Info:
    """The handshake: what is on the other end of the line.

    Attributes:
        rig: which of the three rigs it is.
        protocol: the protocol version the device speaks.
        firmware: the firmware's version (major, minor, patch).
        sample_period_us: the device's sample period [µs].
        channels: the telemetry channels, in the order of TELEMETRY's values.
        reset: why the device last started.
    """

    rig: RigKind
    protocol: int
    firmware: tuple[int, int, int]
    sample_period_us: int
    channels: tuple[Channel, ...]
    reset: ResetCause = ResetCause.POWER_ON


class FrameError(DeviceError):
    """A frame damaged on the line (malformed COBS, CRC mismatch, too short): dropped and
    counted, the sender resends or the next frame goes on."""


def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (polynomial 0x1021, initial 0xFFFF): 0x29B1 for b"123456789".

    binascii's CRC-CCITT is this CRC with the initial value given, computed in C.

    Args:
        data: the bytes to check (a frame's header and body).

    Returns:
        The CRC, 0-65535.
    """
    return binascii.crc_hqx(data, 0xFFFF)


def cobs_encode(data: bytes) -> bytes:
    """Consistent Overhead Byte Stuffing of `data` (at most 254 bytes: one block).

    Args:
        data: the bytes to stuff, at most 254.

    Returns:
        The stuffed bytes, one longer and without a zero (no delimiter).
    """
    out = bytearray([0])
    code_at, code = 0, 1
    for byte in data:
        if byte == 0:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
        else:
            out.append(byte)
            code += 1
    out[code_at] = code
    return bytes(out)


def cobs_decode(data: bytes) -> bytes:
    """The bytes `cobs_encode` was given; DeviceError for a malformed block.

    Args:
        data: a COBS block, without its delimiter.

    Returns:
        The unstuffed bytes.
    """
    out = bytearray()
    i = 0
    while i < len(data):
        code = data[i]
        if code == 0 or i + code > len(data):
            raise FrameError("malformed COBS block")
        out += data[i + 1 : i + code]
        i += code
        if code < 0xFF and i < len(data):
            out.append(0)
    return bytes(out)


def encode(kind: int, seq: int, body: bytes = b"") -> bytes:
    """The wire bytes of one message, delimiter included; DeviceError when it is too long.

    Args:
        kind: the message type.
        seq: the sender's sequence number (taken modulo 65536).
        body: the message's fields.

    Returns:
        COBS(type | seq | body | CRC) followed by the zero delimiter.
    """
    payload = HEADER.pack(kind, seq & 0xFFFF) + body
    payload += CRC.pack(crc16(payload))
    if len(payload) > MAX_FRAME:
        raise DeviceError(f"a frame of {len(payload)} bytes exceeds {MAX_FRAME}")
    return cobs_encode(payload) + b"\0"


def decode(frame: bytes) -> Frame:
    """One message from the bytes between two delimiters.

    FrameError when it is damaged (malformed, too short, CRC mismatch); DeviceError when it
    is intact but longer than the protocol's MAX_FRAME bytes (a sender out of protocol).

    Args:
        frame: the COBS-stuffed bytes between two delimiters.

    Returns:
        The decoded message, its CRC checked.
    """
    payload = cobs_decode(frame)
    if len(payload) < HEADER.size + CRC.size:
        raise FrameError(f"a frame of {len(payload)} bytes is too short")
    (crc,) = CRC.unpack_from(payload, len(payload) - CRC.size)
    if crc16(payload[: -CRC.size]) != crc:
        raise FrameError("CRC mismatch")
    kind, seq = HEADER.unpack_from(payload)
    if len(payload) > MAX_FRAME:
        name = Kind(kind).name if kind in Kind._value2member_map_ else f"type 0x{kind:02x}"
        raise DeviceError(
            f"a frame of {len(payload)} bytes ({name}), more than the protocol's {MAX_FRAME}"
        )
    return Frame(kind, seq, payload[HEADER.size : -CRC.size])


class Deframer:
    """Splits a byte stream into frames at the zero delimiters, across reads, in bounded
    memory: a frame longer than MAX_KEPT bytes is dropped whole and counted in `discarded`
    (no valid frame is that long; its bytes are line noise or a sender out of protocol)."""

    def __init__(self) -> None:
        self._pending = bytearray()
        self._skipping = False  # inside a frame already over MAX_KEPT: drop to its delimiter
        self.discarded = 0

    def feed(self, data: bytes) -> list[bytes]:
        """The complete frames (delimiters removed, empty ones skipped) that `data` ends.

        Args:
            data: the bytes just read from the line.

        Returns:
            The frames completed, still COBS-stuffed (for `decode`), in order.
        """
        *ends, rest = bytes(data).split(b"\0")
        frames = []
        for piece in ends:
            if not self._skipping and len(self._pending) + len(piece) <= MAX_KEPT:
                frames.append(bytes(self._pending + piece))
            elif not self._skipping:
                self.discarded += 1
            self._pending.clear()
            self._skipping = False
        if not self._skipping and len(self._pending) + len(rest) > MAX_KEPT:
            self._pending.clear()
            self._skipping = True
            self.discarded += 1
        if not self._skipping:
            self._pending += rest
        return [f for f in frames if f]


def pack_floats(values: np.ndarray | list[float]) -> bytes:
    """Values as little-endian float32.

    Args:
        values: the numbers to pack, shape (n,).

    Returns:
        4 · n bytes.
    """
    return np.asarray(values, dtype="<f4").tobytes()


def unpack_floats(body: bytes, count: int, offset: int = 0) -> np.ndarray:
    """`count` little-endian float32 from body[offset:] as float64; DeviceError if short.

    Args:
        body: a message's body.
        count: how many float32 to read.
        offset: where the first one starts in `body` [bytes].

    Returns:
        The values, shape (count,).
    """
    if len(body) < offset + 4 * count:
        raise DeviceError(f"expected {count} reals, the body holds {(len(body) - offset) // 4}")
    return np.frombuffer(body, dtype="<f4", count=count, offset=offset).astype(float)


def encode_info(info: Info) -> bytes:
    """The body of INFO.

    Args:
        info: the handshake to send.

    Returns:
        The message's body (docs/protocol.md).
    """
    out = struct.pack(
        "<BBBBBIB",
        info.protocol,
        info.rig,
        *info.firmware,
        info.sample_period_us,
        len(info.channels),
    )
    for channel in info.channels:
        for text in (channel.name, channel.unit):
            data = text.encode("ascii")
            out += struct.pack("<B", len(data)) + data
    return out + struct.pack("<B", info.reset)


def decode_info(body: bytes) -> Info:
    """INFO's body as an Info; DeviceError when it does not decode.

    Args:
        body: the message's body (`encode_info`).

    Returns:
        The handshake it carries.
    """
    try:
        protocol, rig, major, minor, patch, period, count = struct.unpack_from("<BBBBBIB", body)
        at, channels = struct.calcsize("<BBBBBIB"), []
        for _ in range(count):
            texts = []
            for _ in range(2):
                size = body[at]
                if at + 1 + size > len(body):
                    raise ValueError("a channel's text runs past the end")
                texts.append(body[at + 1 : at + 1 + size].decode("ascii"))
                at += 1 + size
            channels.append(Channel(*texts))
        if protocol != PROTOCOL_VERSION:  # the rest may differ: the version is what counts
            return Info(RigKind(rig), protocol, (major, minor, patch), period, tuple(channels))
        if at + 1 != len(body):
            raise ValueError(f"{len(body) - at - 1} bytes after the reset cause")
        reset = ResetCause(body[at])
        return Info(RigKind(rig), protocol, (major, minor, patch), period, tuple(channels), reset)
    except (struct.error, IndexError, ValueError, UnicodeDecodeError) as exc:
        raise DeviceError(f"the handshake does not decode ({exc})") from None
