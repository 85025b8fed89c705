"""`articula rig identify` through the motor and PneuNet firmware in simavr, their pins on a
hidden plant (each constant drawn from 0.5-2× the book's): the motor's R, K, J, L within 3 %
and b within 10 %, the PneuNet's fitted constants within 10 %, as through the Python devices
(tests/identify). The six-chamber firmware's fill table is compiled in: a firmware whose table
is another actuator's is refused in one line, and one built for the hidden actuator
(tools/fill_table.py --plant, make FILL_TABLE=) identifies it within 10 %."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.firmware.conftest import FIRMWARE
from tests.identify.conftest import (
    assert_identified,
    assert_within,
    hidden_motor,
    hidden_pneunet,
    hidden_six_chamber,
)


@pytest.mark.slow
def test_a_hidden_motor_is_identified_through_the_firmware(emulated, cli, tmp_path):
    hidden, plant = hidden_motor(4, tmp_path)
    _, port = emulated("motor", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--json")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert_identified(summary["parameters"], hidden)
    assert summary["unidentifiable"] == []


@pytest.mark.slow
def test_a_hidden_pneunet_is_identified_through_the_firmware(emulated, cli, tmp_path):
    hidden, plant = hidden_pneunet(3, tmp_path)
    _, port = emulated("pneunet", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--json")
    assert proc.returncode == 0, proc.stderr
    assert_within(json.loads(proc.stdout)["parameters"], hidden, 0.10)


@pytest.mark.slow
def test_a_hidden_six_chamber_actuator_is_identified_through_firmware_built_for_it(
    built, emulate_process, cli, tmp_path
):
    hidden, plant = hidden_six_chamber(1, tmp_path)
    refused = cli("emulate", "six-chamber", "--firmware", built / "six_chamber.elf", "--plant",
                  plant)  # fmt: skip
    assert refused.returncode == 2 and "fill_table.h" in refused.stderr  # the default's table
    assert len(refused.stderr.strip().splitlines()) == 1
    header = tmp_path / "fill.h"
    tool = FIRMWARE.parent / "tools/fill_table.py"
    written = subprocess.run([sys.executable, tool, "--plant", plant, "--out", header],
                             capture_output=True, text=True, timeout=120)  # fmt: skip
    assert written.returncode == 0, written.stderr
    build = tmp_path / "fw"
    targets = [f"{build}/six_chamber.elf", f"{build}/harness"]
    made = subprocess.run(["make", "-C", FIRMWARE, f"BUILD={build}", f"FILL_TABLE={header}",
                           *targets], capture_output=True, text=True, timeout=300)  # fmt: skip
    assert made.returncode == 0, made.stderr
    _, port = emulate_process("six-chamber", "--firmware", build / "six_chamber.elf", "--plant",
                              plant)  # fmt: skip
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--json")
    assert proc.returncode == 0, proc.stderr
    assert_within(json.loads(proc.stdout)["parameters"], hidden, 0.10)
