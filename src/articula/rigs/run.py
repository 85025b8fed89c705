"""One run on a rig: start it, keep it alive, take its telemetry until it says it is done,
within a deadline and a bound on what it may send.

During a run the host sends STATUS every HEARTBEAT_S (the device ends a run on its own when
it hears nothing for `host_timeout_ms`, docs/protocol.md); a STATUS that says the run is over
ends the wait even when its DONE was lost. The run must end within its duration plus
DEADLINE_MARGIN_S, with at most the samples its duration holds, each timed inside it: a
device that floods the line, or says "running" forever, ends the run with a DeviceError, and
the host sends it a STOP on the way out of any run that did not end well.
"""

from __future__ import annotations

import contextlib
import math
import struct
import time
from collections.abc import Callable

import numpy as np

from articula.errors import DeviceError
from articula.rigs.link import Link
from articula.rigs.protocol import Frame, Kind, RunEnd, unpack_floats

HEARTBEAT_S = 0.04  # [s] between the host's STATUS frames during a run
HOST_TIMEOUT_MS = 500  # the device's host timeout a run asks for (START's default)
DEADLINE_MARGIN_S = (
    10.0  # [s] a run may take beyond its duration (a device's start, a slow emulator)
)
WRAP_US = 1 << 32  # the device time's modulus [µs] (71.6 minutes)


class DeviceClock:
    """A run's device time, unwrapped: TELEMETRY's u32 µs wraps every 71.6 minutes."""

    def __init__(self) -> None:
        self._last = 0
        self._wraps = 0

    def seconds(self, micros: int) -> float:
        """The run time of a sample [s] from its TELEMETRY time.

        Args:
            micros: the device time TELEMETRY carries [µs], modulo 2^32.

        Returns:
            The time since the run's start [s]: a time below the last one is taken as the
            counter having wrapped.
        """
        if micros < self._last:
            self._wraps += 1
        self._last = micros
        return (micros + self._wraps * WRAP_US) * 1e-6


def run_program(
    link: Link,
    duration: float,
    seed: int,
    on_sample: Callable[[float, np.ndarray], None] | None = None,
    host_timeout_ms: int = HOST_TIMEOUT_MS,
    margin: float = DEADLINE_MARGIN_S,
) -> tuple[np.ndarray, np.ndarray]:
    """Run the rig's loaded program for `duration` and take its telemetry until DONE.

    Args:
        link: the line to the rig, its program loaded.
        duration: the run's length [s].
        seed: the noise seed (an emulated rig draws its sensor noise from it; a real one
            ignores it).
        on_sample: called as on_sample(t, row) with each sample as it arrives (a Recorder's
            add); None: nothing.
        host_timeout_ms: the device ends the run when it hears nothing from the host for this
            long [ms] (20-60000).
        margin: how long the run may take beyond `duration` before the host gives up on it [s].

    Returns:
        The sample times [s, device clock from the run's start], shape (n,), and the
        telemetry rows, shape (n, channels) (one per sample received, one column per
        channel of the handshake).
    """
    channels = len(link.info.channels)
    period = link.info.sample_period_us * 1e-6
    most = math.floor(duration / period + 1e-6) + 2  # samples a run of `duration` can have
    link.command(Kind.STREAM, struct.pack("<H", 1))
    start = link.command(
        Kind.START, struct.pack("<fIH", duration, seed & 0xFFFFFFFF, host_timeout_ms), fresh=True
    )
    deadline = time.monotonic() + duration + margin
    beat = min(HEARTBEAT_S, host_timeout_ms / 5000)
    clock, times, rows = DeviceClock(), [], []
    ended = False

    def take(frame: Frame) -> bool:
        """One frame of the run; True when it is the run's DONE."""
        if frame.kind == Kind.TELEMETRY:
            t = clock.seconds(struct.unpack_from("<I", frame.body)[0])
            if len(times) >= most or t > duration + period:
                raise DeviceError(
                    f"{link.port}: sample {len(times) + 1} came at {t:g} s of a "
                    f"{duration:g} s run with a sample every {period:g} s; the "
                    "device sends more than the run has"
                )
            times.append(t)
            rows.append(unpack_floats(frame.body, channels, 4))
            if on_sample is not None:
                on_sample(times[-1], rows[-1])
        elif frame.kind == Kind.ERROR and int.from_bytes(frame.body[:2], "little") == start:
            text = frame.body[3:].decode("ascii", "replace")
            raise DeviceError(
                f"{link.port}: the rig stopped the run: {text} (code {frame.body[2]})"
            )
        return frame.kind == Kind.DONE and int.from_bytes(frame.body[:2], "little") == start

    try:
        due = time.monotonic() + beat
        while not ended:
            now = time.monotonic()
            if now > deadline:
                raise DeviceError(
                    f"{link.port}: the run of {duration:g} s did not end within "
                    f"{duration + margin:g} s ({len(times)} samples came); the "
                    "device keeps running"
                )
            if now >= due:  # the heartbeat; it also tells when DONE was lost on the way
                status = link.status()
                due = time.monotonic() + beat
                if not status.running:
                    while link.inbox and not ended:  # what came before the answer
                        ended = take(link.inbox.popleft())
                    if not ended and status.ended not in (RunEnd.DONE, RunEnd.NOT_ENDED):
                        raise DeviceError(
                            f"{link.port}: the rig ended the run early "
                            f"({status.ended.name.lower()})"
                        )
                    ended = True
                continue
            frame = link.next_frame(min(due, deadline) - now)
            if frame is not None:
                ended = take(frame)
    except BaseException:
        with contextlib.suppress(DeviceError):  # the line is gone: the host timeout stops it
            link.notify(Kind.STOP)
        raise
    return np.array(times), np.array(rows).reshape(-1, channels)
