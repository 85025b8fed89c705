"""The host against a hostile device (tests/rigs/hostile.py, written from docs/protocol.md
alone) behind a real pty: `rig run` and `rig record` end within their deadline, in one line
naming what came, with exit status 1 (a device error), never hang and never exit 3; and
the link's bounds from Python."""

from __future__ import annotations

import json
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from articula.errors import DeviceError
from articula.rigs.link import Link
from articula.rigs.protocol import Kind
from articula.rigs.run import DeviceClock, run_program

HOSTILE = Path(__file__).with_name("hostile.py")
MOTOR_CONFIG = """
experiment = "motor.current"
duration = 0.5
settle = 0.1
"""
# mode: what the one line says
MODES = {
    "flood": "the device sends more than the run has",
    "flood-at-zero": "the device sends more than the run has",
    "running-forever": "did not end within 10.5 s (0 samples came); the device keeps running",
    "short-telemetry": "a TELEMETRY frame of 2 bytes; the protocol's has 32 here",
    "unknown-type": "the device sent a frame of type 0x99 (0 bytes), which no device sends",
    "long-info": "a frame of 300 bytes (INFO), more than the protocol's 254",
}


@pytest.fixture
def hostile():
    """hostile(mode): the hostile device running in its own process; its pty's path."""
    started = []

    def start(mode: str) -> str:
        proc = subprocess.Popen([sys.executable, HOSTILE, mode], stdout=subprocess.PIPE,
                                text=True)  # fmt: skip
        started.append(proc)
        return proc.stdout.readline().split()[-1]

    yield start
    for proc in started:
        proc.kill()
        proc.wait(10)


@pytest.mark.slow_cases(keep=("flood-run",))
@pytest.mark.parametrize("command", ["run", "record"])
@pytest.mark.parametrize("mode", list(MODES))
def test_a_hostile_device_ends_the_command_with_one_line_and_exit_1(hostile, cli, tmp_path,
                                                                    mode, command):  # fmt: skip
    port = hostile(mode)
    config = tmp_path / "motor.toml"
    config.write_text(MOTOR_CONFIG)
    args = [config] if command == "run" else ["--duration", "0.5"]
    proc = cli("rig", command, port, *args, "--out", tmp_path / "out", timeout=120)
    lines = proc.stderr.splitlines()
    assert proc.returncode == 1, proc.stderr
    assert len(lines) == 1 and lines[0].startswith(f"error: {port}: ")
    assert MODES[mode] in lines[0]
    if mode != "long-info":  # the run had begun: its folder says why it is incomplete
        record = json.loads((tmp_path / "out" / "record.json").read_text())
        assert not record["complete"] and MODES[mode] in record["incomplete"]


def test_a_run_that_does_not_end_stops_at_its_deadline_from_python(hostile):
    link = Link(hostile("running-forever"))
    with link, pytest.raises(DeviceError, match=r"did not end within 0.75 s"):
        run_program(link, 0.25, 0, margin=0.5)


def test_the_device_time_unwraps_past_2_to_the_32_microseconds():
    clock = DeviceClock()
    wrap = 1 << 32
    times = [clock.seconds(m) for m in (wrap - 2000, wrap - 1000, 0, 1000, 2000)]
    assert times == pytest.approx([(wrap - 2000) * 1e-6, (wrap - 1000) * 1e-6, wrap * 1e-6,
                                   (wrap + 1000) * 1e-6, (wrap + 2000) * 1e-6])  # fmt: skip


def test_a_frame_the_protocol_does_not_allow_is_named(hostile):
    link = Link(hostile("short-telemetry"))
    with link, pytest.raises(DeviceError, match=r"a TELEMETRY frame of 2 bytes"):
        link.command(Kind.START, struct.pack("<fI", 1.0, 0))  # it comes with the ACK
        link.next_frame(5.0)
