"""`articula rig identify` through the motor and PneuNet firmware in simavr, their pins on a
hidden plant (each constant drawn from 0.5-2× the book's): the motor's R, K, J, L within 3 %
and b within 10 %, the PneuNet's fitted constants within 10 %, as through the Python devices
(tests/identify). The six-chamber firmware's fill table is compiled for the default actuator:
another is refused in one line."""

from __future__ import annotations

import json

from tests.identify.conftest import (
    assert_identified,
    assert_within,
    hidden_motor,
    hidden_pneunet,
    hidden_six_chamber,
)


def test_a_hidden_motor_is_identified_through_the_firmware(emulated, cli, tmp_path):
    hidden, plant = hidden_motor(4, tmp_path)
    _, port = emulated("motor", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--json")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert_identified(summary["parameters"], hidden)
    assert summary["unidentifiable"] == []


def test_a_hidden_pneunet_is_identified_through_the_firmware(emulated, cli, tmp_path):
    hidden, plant = hidden_pneunet(3, tmp_path)
    _, port = emulated("pneunet", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--json")
    assert proc.returncode == 0, proc.stderr
    assert_within(json.loads(proc.stdout)["parameters"], hidden, 0.10)


def test_the_six_chamber_firmware_refuses_another_actuator_in_one_line(built, cli, tmp_path):
    _, plant = hidden_six_chamber(1, tmp_path)
    proc = cli("emulate", "six-chamber", "--firmware", built / "six_chamber.elf", "--plant", plant)
    assert proc.returncode == 2 and "fill_table.h" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
