"""The firmware's life on the emulated board: a program that starts announces itself with an
INFO nobody asked for (docs/protocol.md, handshake step 4), so a board reset mid-run is
reported by the host as the Python emulator's reset_at is; and `articula emulate --firmware`
stopped with SIGTERM takes its simavr harness with it."""

from __future__ import annotations

import os
import select
import signal
import time

import numpy as np
import pytest

from articula.rigs import protocol
from articula.rigs.firmware import FirmwareRig, Inputs, Pins
from articula.rigs.link import DeviceResetError, Link
from articula.rigs.pneunet import PneuNetPins, PneuNetRig
from articula.rigs.programs import steps
from articula.rigs.protocol import Kind, RigKind
from articula.rigs.run import run_program
from tests.rigs.test_sessions import run_sessions

pytestmark = pytest.mark.firmware
GAINS = np.array([2.0, 1.5, 0.05])


def first_frames(fd: int, count: int, timeout: float = 5.0) -> tuple[bytes, list[bytes]]:
    """What the device sent on `fd` until `count` frames came: (the bytes, the frames)."""
    data, frames, deframer = b"", [], protocol.Deframer()
    deadline = time.monotonic() + timeout
    while len(frames) < count and time.monotonic() < deadline:
        if select.select([fd], [], [], 0.05)[0]:
            chunk = os.read(fd, 4096)
            data += chunk
            frames += deframer.feed(chunk)
    return data, frames


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(("name", "rig"), [("pneunet", RigKind.PNEUNET), ("motor", RigKind.MOTOR),
                                           ("six_chamber", RigKind.SIX_CHAMBER)])  # fmt: skip
def test_a_program_that_starts_sends_its_info_unasked(simavr, name, rig):
    # Opened without pyserial, which empties the line's input on opening.
    fd = os.open(simavr(name), os.O_RDWR | os.O_NOCTTY)
    try:
        data, frames = first_frames(fd, 1)
        assert frames, "no INFO from a program that started"
        assert data.startswith(b"\0")  # a delimiter first: it ends a frame the reset cut
        unasked = protocol.decode(frames[0])
        assert unasked.kind == Kind.INFO and unasked.seq == 0  # its first frame, counting from 0
        assert protocol.decode_info(unasked.body).rig == rig
        os.write(fd, protocol.encode(Kind.HELLO, 1))
        _, frames = first_frames(fd, 1)
        answer = protocol.decode(frames[0])
        assert answer.kind == Kind.INFO and answer.seq == 1 and answer.body == unasked.body
    finally:
        os.close(fd)


class ResetAt:
    """A PneuNet plant whose board's reset button is pressed at the `at`-th control period of
    a run (`rig`: the FirmwareRig, set once it runs)."""

    def __init__(self, at: int) -> None:
        self.plant, self.at, self.periods = PneuNetPins(), at, 0
        self.tick_us, self.program = self.plant.tick_us, self.plant.program
        self.rig: FirmwareRig | None = None

    def start(self, seed: int) -> None:
        self.periods = 0
        self.plant.start(seed)

    def period(self, pins: Pins) -> Inputs:
        self.periods += 1
        if self.periods == self.at and self.rig is not None:
            self.rig.reset()
        return self.plant.period(pins)


def test_a_board_reset_mid_run_is_reported_as_the_python_rigs_reset_at_is(on_plant):
    plant = ResetAt(30)  # 1 s into the run, as the Python emulator's reset_at=1.0
    plant.rig = rig = on_plant("pneunet", plant)
    with Link(rig.path, RigKind.PNEUNET) as link:
        pneunet = PneuNetRig(link, steps((30.0, 60.0), 2.0), 4.0, 7)
        with pytest.raises(DeviceResetError, match="restarted"):
            pneunet(GAINS)
    with Link(rig.path, RigKind.PNEUNET) as link:  # the board that came back shakes hands
        t, _ = run_program(link, 0.5, 0)  # and runs (the plant resets only once a run)
        assert len(t) == 15  # 0.5 s at 30 Hz


def _alive(pid: int) -> bool:
    """Whether process `pid` runs (a zombie nobody reaped has ended)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] not in "ZX"
    except FileNotFoundError:
        return False


def _children(pid: int) -> list[int]:
    """The child processes of `pid`, from /proc."""
    found = []
    for task in os.listdir(f"/proc/{pid}/task"):
        with open(f"/proc/{pid}/task/{task}/children") as children:
            found += [int(child) for child in children.read().split()]
    return found


def test_emulate_with_firmware_stopped_by_sigterm_stops_its_harness(emulated):
    proc, _ = emulated("pneunet")
    harness: list[int] = []
    try:
        harness = _children(proc.pid)
        assert len(harness) == 1
        with open(f"/proc/{harness[0]}/cmdline", "rb") as cmdline:
            assert cmdline.read().split(b"\0")[0].endswith(b"/harness")
        proc.send_signal(signal.SIGTERM)
        proc.wait(10)
        deadline = time.monotonic() + 5
        while _alive(harness[0]) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(harness[0]), "the harness outlived `articula emulate`"
    finally:
        proc.kill()
        proc.wait(10)
        for pid in filter(_alive, harness):  # the test leaves no harness behind either way
            os.kill(pid, signal.SIGKILL)


def test_another_rigs_firmware_is_refused_before_simavr_starts(built, cli):
    proc = cli("emulate", "motor", "--firmware", built / "pneunet.elf")
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"error: --firmware: {built / 'pneunet.elf'} is the pneunet firmware, not the motor "
        "rig's; use firmware/build/motor.elf (make -C firmware)"]  # fmt: skip


def test_each_session_on_the_firmware_runs(emulated, tmp_path):
    # A HELLO opens a session: the second host's START, with the first one's seq, runs.
    _, port = emulated("motor")
    assert run_sessions(port, tmp_path) == [500, 500, 500]
