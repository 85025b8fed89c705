"""The firmware's safety properties tried on the emulated board, the outputs read from the
harness's pin trace (rigs/pin_trace.py): what benchmarks/firmware.py counts and
tests/firmware/test_safety_firmware.py asserts.

- A STOP at a random phase of the control period: every output is off one period after its
  ACK at the latest (the firmware puts them off before it answers).
- A host that goes silent mid-run: the outputs are off within host_timeout_ms plus one
  period of its last frame, and the device says why (ERROR code 5).
- A main loop that hangs (the harness's SIGUSR2), its interrupts still running: the
  watchdog's interrupt puts the outputs off, its reset follows, and the host reports the
  restart as a watchdog's (DeviceResetError).
- Commands in bursts at 1 Mbaud during a run: no byte lost (the USART's overruns, which the
  harness models, as the firmware counts them in STATUS and as the trace shows them).
- A STOP or START with three STATUS behind it in the same write, and bursts that keep the line
  busy through a run's own end (DONE): no byte lost while the firmware changes its outputs
  (issue 47).
"""

from __future__ import annotations

import struct
import time
from dataclasses import dataclass

import numpy as np

from articula.errors import DeviceError
from articula.rigs.firmware import FirmwareRig
from articula.rigs.link import DeviceResetError, Link
from articula.rigs.pin_trace import CPU_HZ, PinTrace, active_outputs
from articula.rigs.protocol import Kind, ResetCause, RigKind
from articula.rigs.run import run_program

LONG_RUN_S = 30.0  # [s] a run that only a STOP, the host's silence or a hang ends
WATCHDOG_S = 0.032  # [s] the watchdog's timeout: 4096 cycles of its 128 kHz oscillator (rig.c)
BYTE_S = 10e-6  # [s] a byte on the line at 1 Mbaud (8N1)
BURST = [(Kind.STATUS, b"")] * 3  # 21 bytes back to back: 210 µs at 1 Mbaud
# [s] a burst that keeps the line busy through a run's end: 200 bytes, which the 256-byte
# receive queue holds even while a run's main loop takes them slower than they come
FILL_S = 0.002
BURST_EVENTS = ("stop", "start", "done")


@dataclass(frozen=True)
class StopTrial:
    """One STOP during a run.

    Attributes:
        phase: where in the control period the STOP's last byte reached the firmware, as a
            fraction of the period (0 at the control tick).
        ack_to_safe_s: from the STOP's ACK leaving the firmware to every output off [s];
            negative when they were off before the ACK went out.
        failed: an output was still (or again) active one period after the ACK.
    """

    phase: float
    ack_to_safe_s: float
    failed: bool


@dataclass(frozen=True)
class HostLossTrial:
    """One host that went silent mid-run.

    Attributes:
        timeout_s: the run's host_timeout_ms [s].
        latency_s: from the host's last frame ending on the line to every output off [s].
        said_why: the device sent the ERROR (code 5, STOPPED) naming the run's START.
    """

    timeout_s: float
    latency_s: float
    said_why: bool


def period_cycles(link: Link) -> int:
    """The rig's control period in CPU cycles.

    Args:
        link: the line to the rig (its handshake's sample period).

    Returns:
        The period [CPU cycles at 16 MHz].
    """
    return round(link.info.sample_period_us * CPU_HZ / 1_000_000)


def _cycle_of(trace: PinTrace, kind: Kind, seq: int, from_host: bool, after: int = 0) -> int:
    """When the first frame of `kind` naming `seq` (a command's seq, or an ACK's acknowledged
    seq) crossed the line after cycle `after` (the trace read on until it shows it)."""
    for _ in range(100_000):
        for f in trace.update().frames:
            if f.from_host != from_host or f.frame is None or f.frame.kind != kind:
                continue
            named = f.frame.seq if from_host else int.from_bytes(f.frame.body[:2], "little")
            if named == seq and f.cycle > after:
                return f.cycle
    raise DeviceError(f"the trace never showed {kind.name} {seq}")


def _trace_past(trace: PinTrace, link: Link, cycle: int) -> None:
    """Ask STATUS until the trace has a frame past `cycle` (the board's time went past it)."""
    while not any(f.cycle > cycle for f in trace.update().frames):
        link.status()


def stop_trial(
    rig: FirmwareRig, trace: PinTrace, link: Link, rng: np.random.Generator
) -> StopTrial:
    """START a long run, STOP it after a random number of its samples, and read the pins.

    Args:
        rig: the firmware on its plant (`trace` is its harness's trace).
        trace: the pin trace of `rig`.
        link: the line to it, the run's settings loaded.
        rng: the draw of when to STOP.

    Returns:
        The trial.
    """
    period = period_cycles(link)
    link.command(Kind.STREAM, struct.pack("<H", 1))
    start = link.command(Kind.START, struct.pack("<fI", LONG_RUN_S, 0), fresh=True)
    for _ in range(int(rng.integers(1, 8))):  # a few samples in: the run is under way
        if link.next_frame(1.0) is None:
            break
    # The phase: the samples leave at one point of the period, so a delay drawn over a few
    # periods of wall time (the board runs faster) puts the STOP anywhere in one. It only
    # chooses the moment; what happened is read from the trace, whatever the delay was.
    time.sleep(rng.uniform(0.0, link.info.sample_period_us * 1e-6))
    stop = link.command(Kind.STOP)
    begun = _cycle_of(trace, Kind.START, start, from_host=True)
    stopped = _cycle_of(trace, Kind.STOP, stop, from_host=True, after=begun)
    acked = _cycle_of(trace, Kind.ACK, stop, from_host=False, after=stopped)
    _trace_past(trace, link, acked + 2 * period)
    run_at = max(c for what, c in trace.events if what == "run" and c <= stopped)
    safe = trace.safe_from(rig.plant.program, acked - 2 * period)
    failed = safe is None or safe > acked + period
    return StopTrial(
        ((stopped - run_at) % period) / period,
        np.inf if safe is None else (safe - acked) / CPU_HZ,
        failed,
    )


def host_loss_trial(
    rig: FirmwareRig, trace: PinTrace, link: Link, timeout_ms: int = 500
) -> HostLossTrial:
    """START a long run, then say nothing (only read): the device must stop it by itself.

    Args:
        rig: the firmware on its plant (`trace` is its harness's trace).
        trace: the pin trace of `rig`.
        link: the line to it, the run's settings loaded.
        timeout_ms: the run's host_timeout_ms [ms].

    Returns:
        The trial.
    """
    start = link.command(Kind.START, struct.pack("<fIH", LONG_RUN_S, 0, timeout_ms), fresh=True)
    said_why = False
    for _ in range(100_000):  # read only: TELEMETRY, then the device's own end
        frame = link.next_frame(1.0)
        if frame is None:
            break
        if frame.kind == Kind.ERROR and int.from_bytes(frame.body[:2], "little") == start:
            said_why = frame.body[2] == 5
            break
    begun = _cycle_of(trace, Kind.START, start, from_host=True)
    acked = _cycle_of(trace, Kind.ACK, start, from_host=False, after=begun)
    _trace_past(trace, link, acked + round(timeout_ms * CPU_HZ / 1000) + 2 * period_cycles(link))
    safe = trace.safe_from(rig.plant.program, acked)
    latency = np.inf if safe is None else (safe - begun) / CPU_HZ
    return HostLossTrial(timeout_ms / 1000, latency, said_why)


def watchdog_trial(rig: FirmwareRig, trace: PinTrace, link: Link) -> tuple[bool, float]:
    """Hang the main loop mid-run (its interrupts on): the host must report the watchdog's
    reset, the outputs must be off within the watchdog's timeout, and the board must answer
    a handshake again.

    Args:
        rig: the firmware on its plant (`trace` is its harness's trace).
        trace: the pin trace of `rig`.
        link: the line to it, the run's settings loaded.

    Returns:
        Whether all of that held, and the time from the hang to every output off [s].
    """
    samples = 0

    def hang_after_some(t: float, row: np.ndarray) -> None:
        nonlocal samples
        samples += 1
        if samples == 5:
            rig.hang()

    try:
        run_program(link, LONG_RUN_S, 0, hang_after_some)
        reported = False
    except DeviceResetError as exc:
        reported = "watchdog" in str(exc)
    trace.update()
    hung = [c for what, c in trace.events if what == "hang"]
    resets = [c for what, c in trace.events if what == "reset" and hung and c > hung[-1]]
    safe = trace.safe_from(rig.plant.program, hung[-1]) if hung else None
    off_s = np.inf if safe is None else (safe - hung[-1]) / CPU_HZ
    with Link(rig.path, link.info.rig) as again:
        back = again.info.reset == ResetCause.WATCHDOG
    return reported and bool(resets) and off_s <= WATCHDOG_S + 1e-3 and back, off_s


def traffic_trial(rig: FirmwareRig, trace: PinTrace, link: Link, bursts: int = 50) -> int:
    """A run with the host's commands in bursts at line rate (STATUS, GET and a refused
    SET_REFERENCE back to back, then STOP), as the telemetry streams: the bytes lost.

    Args:
        rig: the firmware on its plant (`trace` is its harness's trace).
        trace: the pin trace of `rig`.
        link: the line to it.
        bursts: how many bursts.

    Returns:
        Received bytes the firmware lost: its count (STATUS) grown over the run, and the
        overruns the trace shows, whichever is larger.
    """
    before = link.status().rx_overruns
    seen = sum(1 for what, _ in trace.update().events if what == "overrun")
    link.command(Kind.START, struct.pack("<fI", LONG_RUN_S, 0), fresh=True)
    reference = link.setting(Kind.SET_REFERENCE)
    for _ in range(bursts):
        for kind, body in (
            (Kind.STATUS, b""),
            (Kind.GET, bytes([Kind.SET_REFERENCE])),
            (Kind.SET_REFERENCE, reference),
            (Kind.STATUS, b""),
        ):
            link.notify(kind, body)
        link.status()  # the burst answered: the next one
        link.inbox.clear()
    link.command(Kind.STOP)
    lost = link.status().rx_overruns - before
    traced = sum(1 for what, _ in trace.update().events if what == "overrun") - seen
    return max(lost, traced)


@dataclass(frozen=True)
class BurstTrial:
    """One change of the outputs (a STOP, a START, a run's end) with the host's bytes coming
    at full line rate.

    Attributes:
        event: "stop", "start" or "done".
        lost_bytes: received bytes the firmware lost: the trace's overruns, or its own count
            (STATUS) when that is larger.
        covered: the host's bytes were on the line right after the event: for a STOP or a
            START the burst behind it in the same write; for a run's end (the trace's
            "end"), one of the host's bursts was on the line then.
    """

    event: str
    lost_bytes: int
    covered: bool


def _overruns(trace: PinTrace) -> int:
    """The bytes the harness's USART has lost so far (the trace's "overrun" lines)."""
    return sum(1 for what, _ in trace.update().events if what == "overrun")


def _filler() -> bytes:
    """FILL_S of the line at 1 Mbaud that the device drops unanswered: one overlong frame
    (its delimiter last), so it keeps the line busy without filling the send queue."""
    return b"\x55" * round(FILL_S / BYTE_S - 1) + b"\0"


def short_run(link: Link) -> float:
    """A run that ends by itself a few periods in, for `burst_trial`'s "done": its duration;
    on the six-chamber rig, whose run must outlast the actuation's hold, the hold set to two
    periods first.

    Args:
        link: the line to the rig.

    Returns:
        The run's duration [s].
    """
    period = link.info.sample_period_us * 1e-6
    if link.info.rig != RigKind.SIX_CHAMBER:
        return 3 * period
    reference = bytearray(link.setting(Kind.SET_REFERENCE))
    reference[10:14] = struct.pack("<f", 2 * period)  # hold [s] (docs/protocol.md)
    link.command(Kind.SET_REFERENCE, bytes(reference))
    return 5 * period


def burst_trial(trace: PinTrace, link: Link, event: str, run_s: float) -> BurstTrial:
    """A STOP or a START with three STATUS behind it in one write, or a short run that ends by
    itself (DONE) while the host keeps the line busy with bursts: the bytes the firmware lost
    meanwhile.

    Args:
        trace: the pin trace of the firmware's harness.
        link: the line to the firmware, the run's settings loaded.
        event: "stop", "start" or "done".
        run_s: the duration of the run that ends by itself ("done") [s]: a few periods.

    Returns:
        The trial.
    """
    before, seen = link.status().rx_overruns, _overruns(trace)
    covered = True
    if event == "start":
        link.notify_together([(Kind.START, struct.pack("<fI", LONG_RUN_S, 0)), *BURST])
        link.status()  # past the burst: the run is under way
        link.command(Kind.STOP)
    elif event == "stop":
        link.command(Kind.START, struct.pack("<fI", LONG_RUN_S, 0), fresh=True)
        link.next_frame(1.0)  # a sample: the run is under way
        link.notify_together([(Kind.STOP, b""), *BURST])
    else:
        link.command(Kind.START, struct.pack("<fI", run_s, 0), fresh=True)
        for _ in range(100_000):  # a burst, then a STATUS behind it: the line busy most of the time
            link.notify_together([], then=_filler())
            if not link.status().running:
                break
        else:
            raise DeviceError(f"{link.port}: a run of {run_s} s did not end")
        end = max(c for what, c in trace.update().events if what == "end")
        fill_cycles = round(FILL_S * CPU_HZ)
        covered = any(
            f.cycle - fill_cycles <= end <= f.cycle
            for f in trace.frames
            if f.from_host and f.frame is None
        )
    lost = max(link.status().rx_overruns - before, _overruns(trace) - seen)
    link.inbox.clear()
    return BurstTrial(event, lost, covered)


def active_now(rig: FirmwareRig, trace: PinTrace) -> list[str]:
    """The outputs active at the trace's end (what the board drives now).

    Args:
        rig: the firmware on its plant.
        trace: the pin trace of `rig`.

    Returns:
        The active outputs' names ([] in the safe state).
    """
    trace.update()
    return active_outputs(rig.plant.program, trace.pins[-1]) if trace.pins else []
