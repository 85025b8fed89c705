"""`articula rig identify` on emulated motor rigs whose motors are hidden (each constant drawn
from 0.5-2× the book's), with the sensor's noise, the encoder's counts and the PWM's
quantisation on: R, K, J, L within 3 % and b within 10 %; `articula identify` on the saved
recordings gives the same numbers; the fitted plant config runs as a plant."""

from __future__ import annotations

import json

import pytest

from articula.errors import ConfigError
from articula.experiments.motor_on_rig import plant_config
from articula.experiments.rig_identify import MOTOR_EXCITATION, SAFE_CURRENT
from articula.identify.motor import MotorRecording
from tests.identify.conftest import assert_identified, hidden_motor


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_hidden_motor_is_identified_through_the_line(seed, emulate_process, cli, tmp_path):
    hidden, plant = hidden_motor(seed, tmp_path)
    _, port = emulate_process("motor", "--plant", plant)
    proc = cli("rig", "identify", port, "--out", tmp_path / "ident", "--seed", seed, "--json")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert_identified(summary["parameters"], hidden)
    assert summary["unidentifiable"] == []
    assert all(v < 0.1 for v in summary["validation_nrmse"].values())
    assert {p["current_A"] + p["amplitude_A"] for p in summary["excitation"]} <= {
        c + a for c, a, _, _ in MOTOR_EXCITATION
    }
    assert max(p["current_A"] + p["amplitude_A"] for p in summary["excitation"]) <= SAFE_CURRENT
    saved = sorted((tmp_path / "ident").glob("excitation_*"))
    assert len(saved) == len(MOTOR_EXCITATION)
    again = cli("identify", "motor", *saved, "--out", tmp_path / "refit", "--json")
    assert again.returncode == 0, again.stderr
    refit = json.loads(again.stdout)
    assert refit["parameters"] == summary["parameters"]  # the same numbers, bit for bit
    assert refit["standard_errors"] == summary["standard_errors"]
    fitted = plant_config(tmp_path / "ident" / "plant.toml")  # a plant like any other
    assert fitted.rig == "single" and fitted.motor.model_dump() == pytest.approx(
        summary["parameters"]
    )
    assert (tmp_path / "ident" / "fit.png").stat().st_size > 10_000


def test_an_unknown_rig_is_one_line_and_exit_2(cli, tmp_path):
    proc = cli("identify", "arm", tmp_path, "--out", tmp_path / "out")
    assert proc.returncode == 2 and "RIG" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_a_folder_without_a_recording_is_one_line_and_exit_2(cli, tmp_path):
    proc = cli("identify", "motor", tmp_path, "--out", tmp_path / "out")
    assert proc.returncode == 2 and "trace.parquet" in proc.stderr
    assert not (tmp_path / "out").exists()


def test_a_recording_with_the_load_motor_driven_is_refused():
    t = [k * 1e-3 for k in range(200)]
    columns = {"t": t, "v1": [1.0] * 200, "i_meas": [0.1] * 200, "omega_meas": [0.0] * 200,
               "v2": [0.0] * 199 + [0.5]}  # fmt: skip
    with pytest.raises(ConfigError, match="v2"):
        MotorRecording.from_columns(columns, "rec")


def test_a_recording_with_a_nan_is_refused_by_name():
    t = [k * 1e-3 for k in range(200)]
    columns = {"t": t, "v1": [1.0] * 200, "i_meas": [0.1] * 199 + [float("nan")],
               "omega_meas": [0.0] * 200}  # fmt: skip
    with pytest.raises(ConfigError, match="i_meas has NaN"):
        MotorRecording.from_columns(columns, "rec")
