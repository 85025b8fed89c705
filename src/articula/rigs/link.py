"""The host's end of a rig's serial line (pyserial): handshake, acknowledged commands with
bounded retries, and the device's frames with every loss counted.

A command goes out with the host's next sequence number and is sent again when neither its
ACK nor an ERROR naming it arrives within `timeout`; after `retries` resends the link gives
up (DeviceError). Device frames carry the device's own sequence numbers: a gap counts the
frames lost on the way, a damaged frame is counted and skipped (the deframer picks up at the
next delimiter), and an INFO nobody asked for, or a count that starts again from 0, is a
device reset (DeviceResetError): a run never silently goes on across one.
"""

from __future__ import annotations

import struct
import time
from collections import deque
from dataclasses import dataclass

import serial

from articula.errors import DeviceError, PortError
from articula.rigs import protocol
from articula.rigs.protocol import PROTOCOL_VERSION, Frame, Info, Kind, RigKind

BAUD = 1_000_000  # the ATmega16U2 USB bridge of the Mega 2560 runs this rate (docs/protocol.md)


class DeviceResetError(DeviceError):
    """The device restarted (power, watchdog, USB reset) while the host was using it."""


@dataclass
class LinkStats:
    """What the line lost: damaged frames, device frames missing from the sequence, commands
    sent again for want of an acknowledgement.

    Attributes:
        crc_errors: frames dropped as damaged (malformed COBS block or CRC mismatch).
        dropped: device frames missing from the device's sequence numbers.
        resends: commands sent again for want of an ACK or ERROR.
        frames: device frames received intact.
    """

    crc_errors: int = 0
    dropped: int = 0
    resends: int = 0
    frames: int = 0


class Link:
    """A rig behind `port` (a device path, or any pyserial URL); `expect` checks its kind.

    Opening it shakes hands (HELLO, INFO): `info` is what is on the other end.

    Args:
        port: the serial port: a device path (/dev/ttyACM0, an emulator's pty) or a pyserial URL.
        expect: the rig kind the caller needs (PortError for another); None: any.
        baud: the line's rate [bit/s].
        timeout: wait for a command's ACK or ERROR before sending it again [s].
        retries: resends of a command before the link gives up (DeviceError).
    """

    def __init__(
        self,
        port: str,
        expect: RigKind | None = None,
        baud: int = BAUD,
        timeout: float = 0.25,
        retries: int = 3,
    ) -> None:
        try:
            self.serial = serial.serial_for_url(port, baudrate=baud, timeout=0.02)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise PortError(f"{port}: cannot open the port ({exc})") from None
        self.port, self.timeout, self.retries = port, timeout, retries
        self.stats = LinkStats()
        self.inbox: deque[Frame] = deque()  # device frames not yet taken by next_frame
        self._deframer = protocol.Deframer()
        self._seq = 0
        self._device_seq: int | None = None
        self._expecting_info = False
        try:
            self.info = self.handshake(expect)
        except Exception:
            self.serial.close()
            raise

    def handshake(self, expect: RigKind | None) -> Info:
        """HELLO, and the INFO that answers it checked against `expect` and our protocol.

        Args:
            expect: the rig kind required (PortError for another); None: any.

        Returns:
            The device's handshake.
        """
        self._expecting_info = True
        try:
            info = protocol.decode_info(self._exchange(Kind.HELLO, b"", answer=Kind.INFO).body)
        except DeviceError as exc:
            raise PortError(str(exc)) from None
        finally:
            self._expecting_info = False
        if info.protocol != PROTOCOL_VERSION:
            raise PortError(f"{self.port}: the device speaks protocol {info.protocol}, "
                              f"articula {PROTOCOL_VERSION}; update its firmware")  # fmt: skip
        if expect is not None and info.rig != expect:
            raise PortError(f"{self.port}: a {info.rig.name.lower()} rig, not a "
                              f"{expect.name.lower()} rig")  # fmt: skip
        return info

    def command(self, kind: Kind, body: bytes = b"", fresh: bool = False) -> int:
        """Send one command and wait for its acknowledgement (resent on silence).

        Args:
            kind: the command's message type.
            body: the command's body (docs/protocol.md).
            fresh: first forget the device frames taken in and not asked for (a run's START:
                they belong to an earlier run).

        Returns:
            The command's sequence number (a DONE names its START by it).
        """
        if fresh:
            self.inbox.clear()
        self._exchange(kind, body, answer=Kind.ACK)
        return self._seq

    def status(self) -> tuple[bool, int]:
        """Ask the device for its STATUS.

        Returns:
            Whether a run is going on, and the samples of the current (else last) run so far.
        """
        reply = self._exchange(Kind.STATUS, b"", answer=Kind.ACK)
        if len(reply.body) != 7:
            raise DeviceError(f"{self.port}: a STATUS answer of {len(reply.body)} bytes")
        running, samples = struct.unpack_from("<BI", reply.body, 2)
        return bool(running), samples

    def next_frame(self, timeout: float) -> Frame | None:
        """The next device frame (TELEMETRY, DONE, ...) within `timeout`, else None.

        Args:
            timeout: how long to wait for one [s].

        Returns:
            The oldest device frame not yet taken; None when none came in time.
        """
        deadline = time.monotonic() + timeout
        while not self.inbox:
            if not self._read() and time.monotonic() > deadline:
                return None
        return self.inbox.popleft()

    def close(self) -> None:
        """Close the port."""
        self.serial.close()

    def __enter__(self) -> Link:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _exchange(self, kind: Kind, body: bytes, answer: Kind) -> Frame:
        """Send (kind, body) until `answer` naming it comes back; the answer frame."""
        seq = self._seq = (self._seq + 1) & 0xFFFF
        wire = protocol.encode(kind, seq, body)
        for attempt in range(self.retries + 1):
            if attempt:
                self.stats.resends += 1
            self._write(wire)
            deadline = time.monotonic() + self.timeout
            while time.monotonic() < deadline:
                reply = self._take_reply(seq, answer)
                if reply is not None:
                    return reply
                self._read()
        raise DeviceError(f"{self.port}: no answer to {kind.name} after {self.retries + 1} "
                          f"tries; is the rig on and running articula's firmware?")  # fmt: skip

    def _take_reply(self, seq: int, answer: Kind) -> Frame | None:
        """The inbox's answer to command `seq` (removed), if it is there; an ERROR naming it
        raises DeviceError."""
        for frame in list(self.inbox):
            if frame.kind == answer and (answer == Kind.INFO or _acked(frame) == seq):
                self.inbox.remove(frame)
                return frame
            if frame.kind == Kind.ERROR and _acked(frame) == seq:
                self.inbox.remove(frame)
                code, text = frame.body[2], frame.body[3:].decode("ascii", "replace")
                raise DeviceError(f"{self.port}: the rig refused: {text} (code {code})")
        return None

    def _write(self, data: bytes) -> None:
        try:
            self.serial.write(data)
        except (serial.SerialException, OSError) as exc:
            raise DeviceError(f"{self.port}: the line went down ({exc})") from None

    def _read(self) -> bool:
        """Read what the line has (waiting up to the port's timeout); True if a frame came."""
        try:
            data = self.serial.read(max(1, self.serial.in_waiting))
        except (serial.SerialException, OSError) as exc:
            raise DeviceError(f"{self.port}: the line went down ({exc})") from None
        got = False
        for raw in self._deframer.feed(data):
            try:
                frame = protocol.decode(raw)
            except DeviceError:
                self.stats.crc_errors += 1
                continue
            if self._count(frame):
                self.inbox.append(frame)
                got = True
        return got

    def _count(self, frame: Frame) -> bool:
        """Track the device's sequence (gaps are losses); False for a frame to drop. An INFO
        not asked for is a reset when it counts from 0 (a device that starts sends one),
        else the late answer to a HELLO sent again."""
        self.stats.frames += 1
        last, self._device_seq = self._device_seq, frame.seq
        if frame.kind == Kind.INFO and not self._expecting_info:
            if frame.seq == 0:
                raise DeviceResetError(f"{self.port}: the device restarted (a reset or a "
                                       "power loss)")  # fmt: skip
            return False
        if last is not None:
            self.stats.dropped += (frame.seq - last - 1) & 0xFFFF
        return True


def _acked(frame: Frame) -> int:
    """The command sequence number an ACK, ERROR or DONE names."""
    if len(frame.body) < 2:
        raise DeviceError(f"a {Kind(frame.kind).name} without the sequence number it answers")
    return int.from_bytes(frame.body[:2], "little")
