"""`articula rig identify` through the motor firmware in simavr, its pins on a hidden motor
(each constant drawn from 0.5-2× the book's): R, K, J, L within 3 % and b within 10 %, as
through the Python device (tests/identify/test_motor.py)."""

from __future__ import annotations

import json

from tests.identify.conftest import assert_identified, hidden_motor


def test_a_hidden_motor_is_identified_through_the_firmware(emulated, cli, tmp_path):
    hidden, plant = hidden_motor(4, tmp_path)
    _, port = emulated("motor", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--json")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert_identified(summary["parameters"], hidden)
    assert summary["unidentifiable"] == []
