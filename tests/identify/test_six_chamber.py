"""`articula rig identify` on emulated six-chamber rigs whose actuators are hidden (the
silicone's Young's modulus and damping and the valves' orifice drawn from 0.5-2× the defaults),
with the orientation sensor's noise on: each within 10 %, the discharge coefficient named as
given; the last actuation held out predicted; `articula identify` on the saved recordings
gives the same numbers; the fitted actuator runs as a plant."""

from __future__ import annotations

import json

import pytest

from articula.experiments.rig_identify import SIX_CHAMBER_EXCITATION
from articula.experiments.six_chamber_on_rig import plant_config
from tests.identify.conftest import assert_within, hidden_six_chamber


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2])
def test_a_hidden_six_chamber_actuator_is_identified_through_the_line(
    seed, emulate_process, cli, tmp_path
):
    hidden, plant = hidden_six_chamber(seed, tmp_path)
    _, port = emulate_process("six-chamber", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--seed", seed, "--json")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert_within(summary["parameters"], hidden, 0.10)
    assert summary["unidentifiable"] == ["discharge"]
    assert max(summary["validation_nrmse"].values()) < 0.1  # the held-out actuation predicted
    saved = sorted((tmp_path / "ident").glob("excitation_*"))
    assert len(saved) == len(SIX_CHAMBER_EXCITATION)
    again = cli("identify", "six-chamber", *saved, "--out", tmp_path / "refit", "--json")
    assert again.returncode == 0, again.stderr
    assert json.loads(again.stdout)["parameters"] == summary["parameters"]
    fitted = plant_config(tmp_path / "ident" / "plant.toml")  # a plant like any other
    assert fitted.damping == pytest.approx(summary["parameters"]["damping"])
