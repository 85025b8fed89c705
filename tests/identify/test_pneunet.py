"""`articula rig identify` on emulated PneuNet rigs whose actuators are hidden (each fitted
constant drawn from 0.5-2× the defaults), with the flex sensor's noise and ADC on: chamber_tau,
natural_frequency, damping_ratio, pressure_scale and theta_max within 10 %; supply_pressure
and valve_tau named as given, never fitted; `articula identify` on the saved recordings gives
the same numbers; the fitted plant runs as a plant."""

from __future__ import annotations

import json

import pytest

from articula.experiments.pneunet_on_rig import plant_config
from articula.experiments.rig_identify import PNEUNET_EXCITATION, SAFE_PWM
from tests.identify.conftest import assert_within, hidden_pneunet


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2])
def test_a_hidden_pneunet_is_identified_through_the_line(seed, emulate_process, cli, tmp_path):
    hidden, plant = hidden_pneunet(seed, tmp_path)
    _, port = emulate_process("pneunet", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--seed", seed, "--json")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert_within(summary["parameters"], hidden, 0.10)
    assert summary["unidentifiable"] == ["supply_pressure", "valve_tau"]
    assert summary["validation_nrmse"]["angle"] < 0.1
    assert max(p["pwm_count"] for p in summary["excitation"]) <= SAFE_PWM
    saved = sorted((tmp_path / "ident").glob("excitation_*"))
    assert len(saved) == len(PNEUNET_EXCITATION)
    again = cli("identify", "pneunet", *saved, "--out", tmp_path / "refit", "--json")
    assert again.returncode == 0, again.stderr
    assert json.loads(again.stdout)["parameters"] == summary["parameters"]
    fitted = plant_config(tmp_path / "ident" / "plant.toml")  # a plant like any other
    assert fitted.chamber_tau == pytest.approx(summary["parameters"]["chamber_tau"])
