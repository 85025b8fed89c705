"""rigs/link.py and rigs/emulator.py through a real pseudo-terminal and pyserial: the
handshake and its refusals, a PneuNet run equal to the in-process one, losses counted and
never in the trace, a device reset caught."""

from __future__ import annotations

import os
import struct

import numpy as np
import pytest

from articula.book.ch2.tuning import AutoConfig, TuningConfig, auto_run, auto_seed, step_reference
from articula.errors import PortError
from articula.loops.pneunet_pid import SimulatedRig
from articula.plants.pneunet import PneuNetParams
from articula.rigs.emulator import Emulator, Faults
from articula.rigs.link import DeviceResetError, Link
from articula.rigs.pneunet import PneuNetDevice, PneuNetRig
from articula.rigs.programs import steps
from articula.rigs.protocol import Info, Kind, RigKind, RunEnd
from articula.rigs.run import run_program

PARAMS = PneuNetParams()
LEVELS, HOLD = (30.0, 60.0), 2.0
GAINS = np.array([2.0, 1.5, 0.05])


def in_process(seed: int):
    """The same experiment in process (loops.pneunet_pid.SimulatedRig)."""
    return SimulatedRig(PARAMS, step_reference(LEVELS, HOLD, PARAMS.pwm_period), seed)(GAINS)


def test_the_handshake_names_the_rig():
    with Emulator(PneuNetDevice(PARAMS)) as emulator, Link(emulator.path) as link:
        assert link.info.rig == RigKind.PNEUNET
        assert [c.name for c in link.info.channels] == ["reference", "angle", "pwm"]
        assert link.info.sample_period_us == round(PARAMS.pwm_period * 1e6)


def test_a_run_over_the_line_is_the_run_in_process():
    with Emulator(PneuNetDevice(PARAMS)) as emulator, Link(emulator.path) as link:
        rig = PneuNetRig(link, steps(LEVELS, HOLD), len(LEVELS) * HOLD, 7)
        over_the_line = rig(GAINS)
        assert link.stats.crc_errors == link.stats.dropped == 0
    here = in_process(7)
    assert over_the_line.t.size == here.t.size
    # Gains and readings travel as float32: the same numbers to float32's precision.
    assert np.allclose(over_the_line.measured, here.measured, rtol=1e-6, atol=1e-5)
    assert np.array_equal(over_the_line.reference, here.reference)
    assert np.allclose(over_the_line.t, here.t, atol=1e-4)  # the device clock counts whole µs


def test_losses_are_counted_and_never_reach_the_trace():
    faults = Faults(drop=0.02, corrupt=0.02)
    emulator = Emulator(PneuNetDevice(PARAMS), faults=faults, seed=3)
    with emulator, Link(emulator.path, RigKind.PNEUNET) as link:
        rig = PneuNetRig(link, steps(LEVELS, HOLD), len(LEVELS) * HOLD, 7)
        runs = [rig(GAINS) for _ in range(3)]
        stats = link.stats
    assert stats.crc_errors > 0 and stats.dropped > 0  # both faults happened, and were seen
    for k, run in enumerate(runs):
        here = in_process(7 + k)
        index = np.rint(run.t / PARAMS.pwm_period).astype(int)
        assert 0.85 * here.t.size < run.t.size < here.t.size  # the lost samples are missing
        assert np.allclose(run.measured, here.measured[index], rtol=1e-6, atol=1e-5)


def test_a_device_reset_mid_run_is_reported():
    emulator = Emulator(PneuNetDevice(PARAMS), faults=Faults(reset_at=1.0))
    with emulator, Link(emulator.path) as link:
        rig = PneuNetRig(link, steps(LEVELS, HOLD), len(LEVELS) * HOLD, 7)
        with pytest.raises(DeviceResetError, match="restarted"):
            rig(GAINS)


def test_a_silent_port_a_wrong_rig_and_another_protocol_are_refused():
    master, slave = os.openpty()  # a terminal nobody answers on
    try:
        with pytest.raises(PortError, match="no answer to HELLO"):
            Link(os.ttyname(slave), timeout=0.05, retries=1)
    finally:
        os.close(master)
        os.close(slave)
    emulator = Emulator(PneuNetDevice(PARAMS))
    with emulator, pytest.raises(PortError, match="pneunet rig, not a motor rig"):
        Link(emulator.path, RigKind.MOTOR)
    device = PneuNetDevice(PARAMS)
    device.info = Info(RigKind.PNEUNET, 9, (0, 1, 0), 33333, device.info.channels)
    with Emulator(device) as emulator, pytest.raises(PortError, match="protocol 9"):
        Link(emulator.path)
    with pytest.raises(PortError, match="cannot open"):
        Link("/dev/no-such-rig")


@pytest.mark.parametrize(
    ("text", "error"),
    [
        ("drop=2", "probability"),
        ("wobble=1", "unknown fault"),
        ("drop=x", "number"),
        ("delay_ms=-5", "finite time"),
        ("reset_at=nan", "finite time"),
    ],
)
def test_bad_faults_name_the_problem(text, error):
    with pytest.raises(ValueError, match=error):
        Faults.parse(text)


@pytest.mark.slow
def test_coordinate_descent_over_the_line_tunes_as_in_process():
    # Chapter 2's tuner, unchanged, on the emulated rig: the same program, the same seeds.
    config = TuningConfig(auto=AutoConfig(hold=2.0, max_iterations=6))
    levels = (30.0, 60.0)
    here = auto_run(config, levels, 0).result
    with Emulator(PneuNetDevice(config.plant)) as emulator, Link(emulator.path) as link:
        a = config.auto
        rig = PneuNetRig(link, steps(levels, a.hold), len(levels) * a.hold, auto_seed(config, 0))
        there = auto_run(config, levels, 0, rig=rig).result
    assert there.evaluations == here.evaluations
    assert np.allclose(there.k, here.k, rtol=1e-4)  # float32 on the line: the same descent
    assert there.cost == pytest.approx(here.cost, rel=1e-4)


def test_a_slow_rig_gets_its_commands_again_and_the_run_completes():
    # Every reply 0.3 s late, the link waits 0.25 s: each command goes out again (the rig
    # acknowledges a START it already carried out without starting another run).
    emulator = Emulator(PneuNetDevice(PARAMS), faults=Faults(delay_ms=300))
    with emulator, Link(emulator.path, timeout=0.25, retries=3) as link:
        run = PneuNetRig(link, steps(LEVELS, HOLD), len(LEVELS) * HOLD, 7)(GAINS)
        assert link.stats.resends >= 4  # HELLO, SET_GAINS, SET_REFERENCE, STREAM, START...
    here = in_process(7)
    assert np.allclose(run.measured, here.measured, rtol=1e-6, atol=1e-5)


def test_a_rig_that_never_answers_a_command_stops_the_run():
    emulator = Emulator(PneuNetDevice(PARAMS), faults=Faults(delay_ms=400))
    with emulator, pytest.raises(PortError, match="no answer to HELLO after 2 tries"):
        Link(emulator.path, timeout=0.1, retries=1)


def test_the_emulated_device_stops_a_run_when_the_host_goes_silent():
    emulator = Emulator(PneuNetDevice(PARAMS), realtime=True)
    with emulator, Link(emulator.path) as link:
        start = link.command(Kind.START, struct.pack("<fIH", 10.0, 0, 100), fresh=True)
        for _ in range(1000):  # only reading: TELEMETRY, then the device's own end
            frame = link.next_frame(2.0)
            assert frame is not None, "the run went on without the host"
            if frame.kind == Kind.ERROR:
                break
        assert int.from_bytes(frame.body[:2], "little") == start and frame.body[2] == 5
        assert b"host_timeout_ms" in frame.body
        status = link.status()
        assert not status.running and status.ended == RunEnd.HOST_TIMEOUT
        assert 1 <= status.samples <= 10  # about 100 ms at 30 Hz, not the 10 s asked


def test_a_run_with_heartbeats_outlives_the_host_timeout():
    emulator = Emulator(PneuNetDevice(PARAMS), realtime=True)
    with emulator, Link(emulator.path) as link:
        t, _ = run_program(link, 0.5, 0, host_timeout_ms=100)
        assert len(t) == 15 and link.status().ended == RunEnd.DONE
