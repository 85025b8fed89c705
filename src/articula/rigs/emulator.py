"""A rig's device emulated behind a pseudo-terminal: the host opens its path with pyserial as
it would open /dev/ttyACM0, and the simulated plant answers in the protocol.

`--fast` runs samples as fast as the host reads them (the pty's buffer holds the device back
when the host lags); `--realtime` paces them at the rig's sample period. Faults can be
injected on the device's frames: drop (probability a frame is not sent), corrupt (probability
one of its bytes is flipped), delay_ms (the latency of every reply to a command: later
commands are read and answered meanwhile, in order) and reset_at (the
device restarts at that run time [s]: the run ends, its count starts again from 0 and it
announces itself with an INFO, its reset cause "external").

As the firmware does, the device ends a run by itself when the host sends no valid frame for
the START's host_timeout_ms (default 500 ms): it stops and sends an ERROR (code 5, STOPPED)
naming the START. Its silence clock counts only the time it spends waiting for the line, not
the time it computes, so a device busy with a long simulation does not blame the host.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import select
import struct
import threading
import time
import tty
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from articula.errors import ConfigError, DeviceError
from articula.rigs import protocol
from articula.rigs.protocol import ErrorCode, Frame, Info, Kind, ResetCause, RunEnd

HOST_TIMEOUT_MS = 500  # START's default


class Device(Protocol):
    """A rig's program: what the emulator runs for each command and sample."""

    info: Info

    def configure(self, kind: int, body: bytes) -> None:
        """Take a rig-specific command (SET_GAINS, SET_REFERENCE, ...); DeviceError refuses it.

        Args:
            kind: the command's message type (a `Kind`).
            body: the command's body (docs/protocol.md).
        """

    def start(self, duration: float, seed: int) -> None:
        """Begin a run from rest.

        Args:
            duration: the run's length [s].
            seed: the noise seed the sensor's noise is drawn from.
        """

    def sample(self) -> np.ndarray | None:
        """The run's next sample.

        Returns:
            One value per channel of `info`, shape (channels,); None when the run is over.
        """

    def setting(self, kind: int) -> bytes:
        """A setting as its SET_ command carries it (GET); DeviceError for one it has not.

        Args:
            kind: the SET_ command's message type.

        Returns:
            The body the device holds for it.
        """

    def stop(self) -> None:
        """End the run now (actuators off)."""


class PlayedRun:
    """A device's run simulated whole at its first sample, after START is acknowledged (as
    firmware answers at once), then played out a sample per period: for plants that are
    simulated in one batch. A device calls `_begin(compute)` in its start()."""

    _rows: np.ndarray | None = np.zeros((0, 0))
    _n = 0

    def _begin(self, compute: Callable[[], np.ndarray]) -> None:
        """A new run whose samples `compute` returns (one row each)."""
        self._compute, self._rows, self._n = compute, None, 0

    def sample(self) -> np.ndarray | None:
        """The run's next sample.

        Returns:
            The next row of the simulated run, shape (channels,); None when it is over.
        """
        if self._rows is None:
            self._rows = self._compute()
        if self._n >= len(self._rows):
            return None
        self._n += 1
        return self._rows[self._n - 1]

    def stop(self) -> None:
        """End the run."""
        self._rows = np.zeros((0, 0))


@dataclass(frozen=True)
class Faults:
    """Faults injected on the device's side of the line (module docstring).

    Attributes:
        drop: probability that a device frame is not sent, in [0, 1).
        corrupt: probability that one bit of a device frame is flipped, in [0, 1).
        delay_ms: latency of every reply to a command [ms].
        reset_at: run time at which the device restarts [s]; None: never.
    """

    drop: float = 0.0
    corrupt: float = 0.0
    delay_ms: float = 0.0
    reset_at: float | None = None

    @classmethod
    def parse(cls, text: str) -> Faults:
        """Faults from "drop=0.01,corrupt=0.01,delay_ms=20,reset_at=5.0" (any of them).

        Args:
            text: comma-separated name=value pairs (the `--faults` option); "" for none.

        Returns:
            The faults, the ones not named at their defaults (none).
        """
        values: dict[str, float] = {}
        for item in filter(None, (part.strip() for part in text.split(","))):
            name, _, value = item.partition("=")
            if name not in cls.__dataclass_fields__:
                known = ", ".join(cls.__dataclass_fields__)
                raise ConfigError("--faults", f"unknown fault {name!r}; known: {known}")
            try:
                values[name] = float(value)
            except ValueError:
                raise ConfigError("--faults", f"{name} needs a number (got {value!r})") from None
        for name in ("drop", "corrupt"):
            if not 0.0 <= values.get(name, 0.0) < 1.0:
                raise ConfigError("--faults", f"{name} is a probability in [0, 1)")
        for name in ("delay_ms", "reset_at"):
            if not 0.0 <= values.get(name, 0.0) < float("inf"):
                raise ConfigError("--faults", f"{name} is a finite time >= 0")
        return cls(**values)


class Emulator:
    """A device behind a pty; `path` is what the host opens. serve() answers until stop().

    Args:
        device: the rig's program that answers the commands and makes the samples.
        realtime: pace samples at the rig's sample period (default: as fast as the host reads).
        faults: faults injected on the device's frames; None: none.
        seed: seed of the faults' random draws.
    """

    def __init__(
        self, device: Device, realtime: bool = False, faults: Faults | None = None, seed: int = 0
    ) -> None:
        self.device, self.realtime, self.faults = device, realtime, faults or Faults()
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # bytes as they are: no echo, no line editing, no ^C
        self.path = os.ttyname(self._slave)
        self._rng = np.random.default_rng(seed)  # the faults' draws
        self._deframer = protocol.Deframer()
        self._stopped = threading.Event()
        self._seq = 0
        self._run: tuple[int, int, float] | None = None  # (START's seq, samples, start time)
        self._last_start: int | None = None  # the START last carried out (a resend is not)
        self._samples = 0  # samples of the last run
        self._ended = RunEnd.NOT_ENDED
        self._host_timeout = HOST_TIMEOUT_MS * 1e-3  # [s] of the run going on
        self._quiet = 0.0  # [s] spent waiting for the line since the host's last frame
        self._decimation = 1
        self._thread: threading.Thread | None = None
        self._replies: deque[tuple[float, Kind, bytes]] = deque()  # (when due, kind, body)

    def serve(self) -> None:
        """Answer commands and run the device until stop() (or the pty closes)."""
        while not self._stopped.is_set():
            busy = self._run is not None
            wait = 0.0 if busy and not self.realtime else (self._due() if busy else 0.05)
            if self._replies:
                wait = min(wait, self._replies[0][0] - time.monotonic())
            waited = time.monotonic()
            ready, _, _ = select.select([self._master], [], [], max(wait, 0.0))
            self._quiet += time.monotonic() - waited
            if ready:
                try:
                    data = os.read(self._master, 4096)
                except OSError:
                    return  # the pty is gone
                for raw in self._deframer.feed(data):
                    self._handle(raw)
            if self._run is not None and self._quiet >= self._host_timeout:
                self._end_by_itself("no frame from the host within host_timeout_ms; outputs off")
            while self._replies and self._replies[0][0] <= time.monotonic():
                _, kind, body = self._replies.popleft()
                self._send(kind, body)
            if self._run is not None and self._due() <= 0.0:
                self._step()

    def start(self) -> Emulator:
        """serve() on a daemon thread.

        Returns:
            The emulator itself.
        """
        self._thread = threading.Thread(target=self.serve, name="articula-emulator", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """End serve() and close the pty (the host then sees the line go down)."""
        self._stopped.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        for fd in (self._master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)

    def __enter__(self) -> Emulator:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _due(self) -> float:
        """Seconds until the next sample is due (realtime), 0 when running fast."""
        if self._run is None or not self.realtime:
            return 0.0
        _, samples, started = self._run
        period = self.device.info.sample_period_us * 1e-6
        return started + samples * period - time.monotonic()

    def _end_by_itself(self, why: str) -> None:
        """The device ends the run (safe state) and says why, naming its START."""
        seq, samples, _ = self._run
        self.device.stop()
        self._run, self._samples, self._ended = None, samples, RunEnd.HOST_TIMEOUT
        self._send(Kind.ERROR, struct.pack("<HB", seq, ErrorCode.STOPPED) + why.encode())

    def _handle(self, raw: bytes) -> None:
        """Decode one command and answer it (a damaged one is ignored: the host resends)."""
        try:
            frame = protocol.decode(raw)
        except DeviceError:
            return
        self._quiet = 0.0
        try:
            self._execute(frame)
        except (DeviceError, struct.error) as exc:
            self._reply(
                Kind.ERROR,
                struct.pack("<HB", frame.seq, ErrorCode.BAD_VALUE)
                + str(exc).encode("ascii", "replace")[:200],
            )

    def _execute(self, frame: Frame) -> None:
        """Carry out one command and acknowledge it."""
        if frame.kind == Kind.HELLO:  # a new session: its START may reuse the last one's seq
            if self._run is None:
                self._last_start = None
            self._reply(Kind.INFO, protocol.encode_info(self.device.info))
            return
        status = b""
        if frame.kind == Kind.START:
            if self._run is not None and self._run[0] != frame.seq:
                raise DeviceError("a run is going on; STOP it first")
            if frame.seq != self._last_start:  # a START sent again is only acknowledged
                duration, seed, timeout = _start(frame.body)
                self.device.start(duration, seed)
                self._run, self._last_start = (frame.seq, 0, time.monotonic()), frame.seq
                self._host_timeout, self._ended = timeout * 1e-3, RunEnd.NOT_ENDED
        elif frame.kind == Kind.STATUS:
            samples = self._run[1] if self._run is not None else self._samples
            status = struct.pack("<BIHB", self._run is not None, samples, 0, self._ended)
        elif frame.kind == Kind.GET:
            if len(frame.body) != 1:
                raise DeviceError("GET takes the type of a SET_ command (u8)")
            status = self.device.setting(frame.body[0])
        elif frame.kind == Kind.STOP:
            self.device.stop()
            if self._run is not None:
                self._run, self._samples, self._ended = None, self._run[1], RunEnd.STOP
        elif frame.kind == Kind.STREAM:
            (self._decimation,) = struct.unpack("<H", frame.body)
        else:
            self.device.configure(frame.kind, frame.body)
        self._reply(Kind.ACK, struct.pack("<H", frame.seq) + status)

    def _step(self) -> None:
        """One sample of the run; its telemetry; DONE at its end; a reset when one is due."""
        seq, samples, started = self._run
        period = self.device.info.sample_period_us * 1e-6
        if self.faults.reset_at is not None and samples * period >= self.faults.reset_at:
            self.device.stop()
            self._run, self._seq, self._last_start = None, 0, None
            self._replies.clear()  # what a device had not sent yet dies with it
            self.faults = Faults(self.faults.drop, self.faults.corrupt, self.faults.delay_ms)
            info = dataclasses.replace(self.device.info, reset=ResetCause.EXTERNAL)
            self._send(Kind.INFO, protocol.encode_info(info))
            return
        values = self.device.sample()
        if values is None:
            self._run, self._samples, self._ended = None, samples, RunEnd.DONE
            self._send(Kind.DONE, struct.pack("<HI", seq, samples))
            return
        self._run = (seq, samples + 1, started)
        if self._decimation and samples % self._decimation == 0:
            micros = round(samples * self.device.info.sample_period_us) & 0xFFFFFFFF
            self._send(Kind.TELEMETRY, struct.pack("<I", micros) + protocol.pack_floats(values))

    def _reply(self, kind: Kind, body: bytes) -> None:
        """An answer to a command: sent now, or after the delay fault's latency."""
        if self.faults.delay_ms:
            self._replies.append((time.monotonic() + self.faults.delay_ms * 1e-3, kind, body))
        else:
            self._send(kind, body)

    def _send(self, kind: Kind, body: bytes) -> None:
        """One frame to the host, through the faults; every frame takes the next sequence
        number as it goes out."""
        wire = protocol.encode(kind, self._seq, body)
        self._seq = (self._seq + 1) & 0xFFFF
        if self._rng.random() < self.faults.drop:
            return
        if self._rng.random() < self.faults.corrupt:
            damaged = bytearray(wire)
            damaged[self._rng.integers(len(wire) - 1)] ^= 1 << int(self._rng.integers(8))
            wire = bytes(damaged)
        try:
            os.write(self._master, wire)
        except OSError:
            self._stopped.set()  # the pty is gone


def _start(body: bytes) -> tuple[float, int, int]:
    """START's duration [s], seed and host timeout [ms]; DeviceError when it does not decode."""
    if len(body) not in (8, 10):
        raise DeviceError("START takes a duration, a seed and host_timeout_ms")
    duration, seed = struct.unpack_from("<fI", body)
    timeout = struct.unpack_from("<H", body, 8)[0] if len(body) == 10 else HOST_TIMEOUT_MS
    if not 20 <= timeout <= 60000:
        raise DeviceError("START: host_timeout_ms must be 20-60000")
    return duration, seed, timeout
