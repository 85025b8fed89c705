"""One run on a rig: start it, take its telemetry until it says it is done."""

from __future__ import annotations

import struct
from collections.abc import Callable

import numpy as np

from articula.rigs.link import Link
from articula.rigs.protocol import Kind, unpack_floats

QUIET = 0.3  # [s] without a frame during a run before the host asks the rig for its status


def run_program(
    link: Link,
    duration: float,
    seed: int,
    on_sample: Callable[[float, np.ndarray], None] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Run the rig's loaded program for `duration` and take its telemetry until DONE.

    Args:
        link: the line to the rig, its program loaded.
        duration: the run's length [s].
        seed: the noise seed (an emulated rig draws its sensor noise from it; a real one
            ignores it).
        on_sample: called as on_sample(t, row) with each sample as it arrives (a Recorder's
            add); None: nothing.

    Returns:
        The sample times [s, device clock from the run's start], shape (n,), and the
        telemetry rows, shape (n, channels) (one per sample received, one column per
        channel of the handshake).
    """
    channels = len(link.info.channels)
    link.command(Kind.STREAM, struct.pack("<H", 1))
    start = link.command(Kind.START, struct.pack("<fI", duration, seed & 0xFFFFFFFF), fresh=True)
    times, rows = [], []
    while True:
        frame = link.next_frame(QUIET)
        if frame is None:  # DONE lost on the way, or the rig stalled: ask it
            running, _ = link.status()
            if not running:
                break
            continue
        if frame.kind == Kind.TELEMETRY:
            (micros,) = struct.unpack_from("<I", frame.body)
            times.append(micros * 1e-6)
            rows.append(unpack_floats(frame.body, channels, 4))
            if on_sample is not None:
                on_sample(times[-1], rows[-1])
        elif frame.kind == Kind.DONE and int.from_bytes(frame.body[:2], "little") == start:
            break
    return np.array(times), np.array(rows).reshape(-1, channels)
