"""`articula emulate` and `articula rig info` as a user runs them: real processes, a real
pseudo-terminal; errors are one line, exit 2."""

from __future__ import annotations

import json
import signal
import subprocess

import pytest

from tests.conftest import ARTICULA


@pytest.fixture
def emulated_pneunet():
    """`articula emulate pneunet --fast` running; its device path."""
    proc = subprocess.Popen([ARTICULA, "emulate", "pneunet", "--fast"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)  # fmt: skip
    line = proc.stdout.readline()
    assert "pneunet rig at /dev/" in line, proc.stderr.read()
    yield line.split(" at ")[1].split()[0]
    proc.send_signal(signal.SIGINT)
    assert proc.wait(10) == 0
    assert proc.stderr.read() == ""


def test_rig_info_of_an_emulated_pneunet(emulated_pneunet, cli):
    proc = cli("rig", "info", emulated_pneunet, "--json")
    assert proc.returncode == 0, proc.stderr
    info = json.loads(proc.stdout)
    assert info["rig"] == "pneunet" and info["protocol"] == 1
    assert [c["unit"] for c in info["channels"]] == ["deg", "deg", "counts"]
    text = cli("rig", "info", emulated_pneunet).stdout
    assert "angle [deg]" in text


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["rig", "info", "/dev/no-such-rig"], "cannot open the port"),
        (["rig", "info", "/dev/null"], "cannot open the port"),
        (["emulate", "motor"], "no emulator for 'motor'"),
        (["emulate", "pneunet", "--faults", "drop=3"], "probability"),
    ],
)
def test_bad_ports_and_options_are_one_line_and_exit_2(cli, args, words):
    proc = cli(*args)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and words in proc.stderr
