"""The host's end of a rig's serial line (pyserial): handshake, acknowledged commands with
bounded retries, and the device's frames with every loss counted.

A command goes out with the host's next sequence number and is sent again when neither its
ACK nor an ERROR naming it arrives within `timeout`; after `retries` resends the link gives
up (DeviceError). Device frames carry the device's own sequence numbers: a gap counts the
frames lost on the way, a damaged frame is counted and skipped (the deframer picks up at the
next delimiter), and an INFO nobody asked for, or a count that starts again from 0, is a
device reset (DeviceResetError): a run never silently goes on across one.

Every wait has a deadline and every buffer a bound: a command waits at most (retries + 1)
· timeout, a write at most WRITE_TIMEOUT; the frames not yet taken are at most MAX_INBOX. An
intact frame that breaks the protocol (a TELEMETRY body of the wrong length, an INFO longer
than a frame, a type the protocol does not have) is a DeviceError naming what came.
"""

from __future__ import annotations

import struct
import time
from collections import deque
from dataclasses import dataclass

import serial

from articula.errors import DeviceError, PortError
from articula.rigs import protocol
from articula.rigs.protocol import (
    PROTOCOL_VERSION,
    Frame,
    FrameError,
    Info,
    Kind,
    ResetCause,
    RigKind,
    RunEnd,
)

BAUD = 1_000_000  # the ATmega16U2 USB bridge of the Mega 2560 runs this rate (docs/protocol.md)
WRITE_TIMEOUT = 1.0  # [s] a device that takes no bytes for this long has stopped reading
MAX_INBOX = 4096  # device frames waiting to be taken; more: the device floods the line
RESET_WORDS = {
    ResetCause.POWER_ON: "a power loss",
    ResetCause.EXTERNAL: "its reset pin: the button, the USB line or the emulator",
    ResetCause.WATCHDOG: "its watchdog: the program stopped; its outputs went off",
    ResetCause.BROWN_OUT: "its supply dropped (brown-out)",
}


class DeviceResetError(DeviceError):
    """The device restarted (power, watchdog, USB reset) while the host was using it."""


class NoAnswerError(DeviceError):
    """A command got neither its answer nor an ERROR after every resend."""


@dataclass
class LinkStats:
    """What the line lost: damaged frames, device frames missing from the sequence, commands
    sent again for want of an acknowledgement.

    Attributes:
        crc_errors: frames dropped as damaged (malformed COBS block, CRC mismatch, overlong).
        dropped: device frames missing from the device's sequence numbers.
        resends: commands sent again for want of an ACK or ERROR.
        frames: device frames received intact.
    """

    crc_errors: int = 0
    dropped: int = 0
    resends: int = 0
    frames: int = 0


@dataclass(frozen=True)
class Status:
    """A device's answer to STATUS.

    Attributes:
        running: whether a run goes on (its DONE not sent yet).
        samples: the samples of the current run so far, else of the last one.
        rx_overruns: bytes from the host the device lost since it started (its USART's data
            overruns and a full receive queue).
        ended: how the last run ended.
    """

    running: bool
    samples: int
    rx_overruns: int
    ended: RunEnd


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
            self.serial = serial.serial_for_url(
                port, baudrate=baud, timeout=0.02, write_timeout=WRITE_TIMEOUT
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            raise PortError(f"{port}: cannot open the port ({exc})") from None
        self.port, self.timeout, self.retries = port, timeout, retries
        self.stats = LinkStats()
        self.inbox: deque[Frame] = deque()  # TELEMETRY, DONE and unasked ERRORs not yet taken
        self.info: Info | None = None
        self._deframer = protocol.Deframer()
        self._seq = 0
        self._device_seq: int | None = None
        self._waiting: tuple[int, Kind] | None = None  # the command awaiting its answer
        self._answer: Frame | None = None
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
        try:  # silence is bad input (a port without a rig); a device out of protocol is not
            info = protocol.decode_info(self._exchange(Kind.HELLO, b"", answer=Kind.INFO).body)
        except NoAnswerError as exc:
            raise PortError(str(exc)) from None
        if info.protocol != PROTOCOL_VERSION:
            raise PortError(
                f"{self.port}: the device speaks protocol {info.protocol}, "
                f"articula {PROTOCOL_VERSION}; update its firmware"
            )
        if expect is not None and info.rig != expect:
            raise PortError(
                f"{self.port}: a {info.rig.name.lower()} rig, not a {expect.name.lower()} rig"
            )
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

    def notify(self, kind: Kind, body: bytes = b"") -> None:
        """Send one command once, without waiting for its answer (a STOP on the way out of a
        failed run: the device's host timeout covers a loss).

        Args:
            kind: the command's message type.
            body: the command's body.
        """
        self._seq = (self._seq + 1) & 0xFFFF
        self._write(protocol.encode(kind, self._seq, body))

    def notify_together(self, commands: list[tuple[Kind, bytes]], then: bytes = b"") -> list[int]:
        """Send several commands in one write, back to back on the line, without waiting
        for their answers (a test of the device's reception at full line rate).

        Args:
            commands: (message type, body) of each, in order.
            then: bytes to write after them in the same write (e.g. damaged frames, which the
                device drops unanswered, to keep the line busy).

        Returns:
            Their sequence numbers.
        """
        wire, seqs = b"", []
        for kind, body in commands:
            self._seq = (self._seq + 1) & 0xFFFF
            wire += protocol.encode(kind, self._seq, body)
            seqs.append(self._seq)
        self._write(wire + then)
        return seqs

    def status(self) -> Status:
        """Ask the device for its STATUS.

        Returns:
            Whether a run is going on, its samples so far, the device's receive losses and
            how the last run ended.
        """
        reply = self._exchange(Kind.STATUS, b"", answer=Kind.ACK)
        if len(reply.body) != 10:
            raise DeviceError(
                f"{self.port}: a STATUS answer of {len(reply.body)} bytes; the protocol's is 10"
            )
        running, samples, overruns, ended = struct.unpack_from("<BIHB", reply.body, 2)
        if ended not in RunEnd._value2member_map_:
            raise DeviceError(f"{self.port}: a STATUS answer with run end {ended}")
        return Status(bool(running), samples, overruns, RunEnd(ended))

    def setting(self, kind: Kind) -> bytes:
        """The device's setting `kind` (a SET_ command) as that command carries it (GET).

        Args:
            kind: SET_GAINS, SET_REFERENCE, SET_OUTPUT or SET_DAMPING.

        Returns:
            The body the device holds for it.
        """
        return self._exchange(Kind.GET, bytes([kind]), answer=Kind.ACK).body[2:]

    def next_frame(self, timeout: float) -> Frame | None:
        """The next device frame (TELEMETRY, DONE, an ERROR nobody waits for) within
        `timeout`, else None.

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
        self._waiting, self._answer = (seq, answer), None
        try:
            for attempt in range(self.retries + 1):
                if attempt:
                    self.stats.resends += 1
                self._write(wire)
                deadline = time.monotonic() + self.timeout
                while self._answer is None and time.monotonic() < deadline:
                    self._read()
                if self._answer is not None:
                    return self._answered()
        finally:
            self._waiting = None
        raise NoAnswerError(
            f"{self.port}: no answer to {kind.name} after {self.retries + 1} "
            f"tries; is the rig on and running articula's firmware?"
        )

    def _answered(self) -> Frame:
        """The awaited answer; an ERROR naming the command raises DeviceError."""
        frame = self._answer
        if frame.kind == Kind.ERROR:
            code, text = frame.body[2], frame.body[3:].decode("ascii", "replace")
            raise DeviceError(f"{self.port}: the rig refused: {text} (code {code})")
        return frame

    def _write(self, data: bytes) -> None:
        try:
            self.serial.write(data)
        except serial.SerialTimeoutException:
            raise DeviceError(
                f"{self.port}: the device took no bytes for {WRITE_TIMEOUT:g} s; "
                "it stopped reading the line"
            ) from None
        except (serial.SerialException, OSError) as exc:
            raise DeviceError(f"{self.port}: the line went down ({exc})") from None

    def _read(self) -> bool:
        """Read what the line has (waiting up to the port's timeout); True if a frame came."""
        try:
            data = self.serial.read(min(max(1, self.serial.in_waiting), 65536))
        except (serial.SerialException, OSError) as exc:
            raise DeviceError(f"{self.port}: the line went down ({exc})") from None
        got = False
        discarded = self._deframer.discarded
        for raw in self._deframer.feed(data):
            try:
                frame = protocol.decode(raw)
            except FrameError:
                self.stats.crc_errors += 1
                continue
            except DeviceError as exc:
                raise DeviceError(f"{self.port}: {exc}") from None
            got |= self._route(frame)
        self.stats.crc_errors += self._deframer.discarded - discarded
        return got

    def _route(self, frame: Frame) -> bool:
        """Count an intact frame and put it where it belongs: the awaited answer, the inbox,
        or nowhere (a late answer to a command sent again); True if it is kept."""
        self._check(frame)
        self.stats.frames += 1
        last, self._device_seq = self._device_seq, frame.seq
        waiting = self._waiting
        if frame.kind == Kind.INFO:
            if waiting is not None and waiting[1] == Kind.INFO:
                self._answer = frame
                return True
            if frame.seq == 0:  # a device that starts counts from 0 and says so
                cause = protocol.decode_info(frame.body).reset
                raise DeviceResetError(f"{self.port}: the device restarted ({RESET_WORDS[cause]})")
            return False  # a late answer to a HELLO sent again
        if last is not None:
            self.stats.dropped += (frame.seq - last - 1) & 0xFFFF
        answers = waiting is not None and (
            (frame.kind == Kind.ACK and waiting[1] == Kind.ACK) or frame.kind == Kind.ERROR
        )
        if answers and _acked(frame) == waiting[0]:  # its ACK, or an ERROR naming it
            self._answer = frame
            return True
        if frame.kind == Kind.ACK or self.info is None:
            return False  # a late answer; or, before the handshake, an earlier session's
        if len(self.inbox) >= MAX_INBOX:
            raise DeviceError(
                f"{self.port}: more than {MAX_INBOX} frames came that nothing "
                "asked for; the device floods the line"
            )
        self.inbox.append(frame)
        return True

    def _check(self, frame: Frame) -> None:
        """DeviceError for an intact frame the protocol does not allow, naming what came."""
        size = len(frame.body)
        kind = Kind(frame.kind).name if frame.kind in Kind._value2member_map_ else None
        if kind is None or frame.kind < 0x80:
            what = kind or f"type 0x{frame.kind:02x}"
            raise DeviceError(
                f"{self.port}: the device sent a frame of {what} ({size} "
                "bytes), which no device sends"
            )
        need = {Kind.ACK: (2, None), Kind.ERROR: (3, None), Kind.DONE: (6, 6)}.get(frame.kind)
        if frame.kind == Kind.TELEMETRY and self.info is not None:
            need = (4 + 4 * len(self.info.channels),) * 2
        if need is not None and (size < need[0] or (need[1] is not None and size > need[1])):
            exact = f"{need[0]}" if need[0] == need[1] else f"at least {need[0]}"
            raise DeviceError(
                f"{self.port}: a {kind} frame of {size} bytes; the protocol's has {exact} here"
            )
        if frame.kind == Kind.INFO:
            try:
                protocol.decode_info(frame.body)
            except DeviceError as exc:
                raise DeviceError(f"{self.port}: an INFO frame of {size} bytes: {exc}") from None


def _acked(frame: Frame) -> int:
    """The command sequence number an ACK, ERROR or DONE names."""
    return int.from_bytes(frame.body[:2], "little")
