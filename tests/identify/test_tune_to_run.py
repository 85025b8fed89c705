"""From an emulated rig to a tuned run, with no file written by hand: `emulate` → `rig
identify` (its excitation recorded) → `rig tune --model` (tuning.json and tuned.toml) →
`rig run PORT tuned.toml` (the rig beside its model) → `run tuned.toml` (the model alone)."""

from __future__ import annotations

import json
import tomllib

import pytest


@pytest.mark.slow
def test_the_tuned_config_runs_on_the_rig_and_on_the_model_without_an_edit(
    emulate_process, cli, tmp_path
):
    _, port = emulate_process("pneunet")
    identified = cli("rig", "identify", port, "--out", tmp_path / "ident")
    assert identified.returncode == 0, identified.stderr
    model = tmp_path / "ident" / "plant.toml"
    tuned = cli("rig", "tune", port, "--out", tmp_path / "tune", "--model", model, "--json")
    assert tuned.returncode == 0, tuned.stderr
    result, config = json.loads(tuned.stdout), tmp_path / "tune" / "tuned.toml"
    written = tomllib.loads(config.read_text())
    assert written["controller"]["gains"] == [result["gains"]]
    assert written["plant"] == pytest.approx(tomllib.loads(model.read_text())["plant"])
    on_rig = cli("rig", "run", port, config, "--out", tmp_path / "rig", "--json")
    assert on_rig.returncode == 0, on_rig.stderr
    both = json.loads(on_rig.stdout)
    alone = cli("run", config, "--out", tmp_path / "sim", "--json")
    assert alone.returncode == 0, alone.stderr
    simulated = json.loads(alone.stdout)["metrics"]
    assert both["model_metrics"]["cost_median"] == simulated["cost_median"]  # the same model
    # the rig and its fitted model agree on the tuned gains' cost M (2.5) within 10 %
    assert both["metrics"]["cost_median"] == pytest.approx(simulated["cost_median"], rel=0.1)
    assert both["metrics"]["cost_median"] == pytest.approx(result["cost"], rel=0.1)


@pytest.mark.slow
def test_rig_run_shows_the_rig_beside_its_model(emulate_process, cli, tmp_path):
    _, port = emulate_process("pneunet")
    tuned = cli("rig", "tune", port, "--method", "manual", "--levels", "45", "--out",
                tmp_path / "tune")  # fmt: skip
    assert tuned.returncode == 0, tuned.stderr
    assert "tuned.toml" in tuned.stdout
    shown = cli("rig", "run", port, tmp_path / "tune" / "tuned.toml", "--out", tmp_path / "rig")
    assert shown.returncode == 0, shown.stderr
    header = next(line for line in shown.stdout.splitlines() if "metric" in line)
    assert "rig" in header and "model" in header
