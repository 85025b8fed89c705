"""`articula rig tune --model`: on an emulated PneuNet rig hiding an actuator drawn from
0.5-2× the defaults, tuning on the model `rig identify` fitted, then confirming on the rig,
reaches an M within 10 % of `rig tune` on the rig alone with at most a fifth of its
experiments on the rig."""

from __future__ import annotations

import json

import pytest

from tests.identify.conftest import hidden_pneunet


@pytest.mark.slow
def test_tuning_on_the_fitted_model_needs_a_fifth_of_the_rig_experiments(
    emulate_process, cli, tmp_path
):
    _, plant = hidden_pneunet(5, tmp_path)
    _, port = emulate_process("pneunet", "--plant", plant)
    alone = cli("rig", "tune", port, "--out", tmp_path / "alone", "--json")
    assert alone.returncode == 0, alone.stderr
    identified = cli("rig", "identify", port, "--out", tmp_path / "ident", "--json")
    assert identified.returncode == 0, identified.stderr
    model = tmp_path / "ident" / "plant.toml"
    confirmed = cli("rig", "tune", port, "--out", tmp_path / "model", "--model", model, "--json")
    assert confirmed.returncode == 0, confirmed.stderr
    on_rig, on_model = json.loads(alone.stdout), json.loads(confirmed.stdout)
    assert on_model["cost"] <= 1.10 * on_rig["cost"]
    assert on_model["experiments"] <= on_rig["experiments"] / 5
    assert on_model["model_experiments"] > on_model["experiments"]  # the search ran on the model
    saved = json.loads((tmp_path / "model" / "tuning.json").read_text())
    assert saved["experiments"] == on_model["experiments"]


def test_a_model_with_another_tuner_is_one_line_and_exit_2(cli, tmp_path):
    proc = cli("rig", "tune", "/dev/null", "--out", tmp_path / "t", "--method", "manual",
               "--model", tmp_path / "plant.toml")  # fmt: skip
    assert proc.returncode == 2 and "--model" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
