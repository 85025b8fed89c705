"""Every base input is accepted, cheaply: the fuzzer mutates valid inputs, not refused ones."""

from __future__ import annotations

import json

import pytest

from tests.fuzz import bases
from tests.fuzz.contract import Example
from tests.fuzz.fuzzing import Fuzz
from tests.fuzz.inputs import write_toml

pytestmark = pytest.mark.fuzz

CHEAP_SECONDS = 10.0  # [s] a base runs in well under a second; this only allows for load

RUNS = {
    "motor.current": bases.MOTOR_CURRENT,
    "pneunet.pid": bases.PNEUNET_PID,
    "softarm.damping": bases.SOFTARM_DAMPING,
}


def _accepted(fuzz: Fuzz, command: str, args: list[str], files: dict[str, dict]) -> dict:
    folder = fuzz.workdir()
    inputs = {name: write_toml(folder / name, data) for name, data in files.items()}
    out = folder / "out" if "--out" in args else None
    outcome = fuzz.check(Example(command, args, folder, out, True, (), inputs, "none"))
    assert outcome.status == 0, outcome.stderr
    assert outcome.wall < CHEAP_SECONDS, outcome.describe()
    return json.loads(outcome.stdout)


@pytest.mark.parametrize("name", sorted(RUNS))
def test_run_base(fuzz: Fuzz, name: str):
    args = ["run", "config.toml", "--out", "out", "--json"]
    record = _accepted(fuzz, f"run {name}", args, {"config.toml": RUNS[name]})
    assert record["experiment"] == name


@pytest.mark.parametrize("name", sorted(bases.PLANS))
def test_plan_base(fuzz: Fuzz, name: str):
    args = ["plan", "scene.toml", "--out", "out", "--json"]
    record = _accepted(fuzz, "plan", args, {"scene.toml": bases.PLANS[name]})
    assert record["experiment"] == "baornn.plan"


@pytest.mark.parametrize("name", sorted(bases.SCENES))
def test_scene_base(fuzz: Fuzz, name: str):
    args = ["scene", "check", "scene.toml", "--q", bases.Q0, "--json"]
    result = _accepted(fuzz, "scene check", args, {"scene.toml": bases.SCENES[name]})
    assert len(result["ee_position"]) == 3


def test_motor_params_base(fuzz: Fuzz):
    args = ["motor", "analyze", "--params", "motor.toml", "--json"]
    result = _accepted(fuzz, "motor analyze", args, {"motor.toml": bases.MOTOR_PARAMS})
    assert result["params"]["R"] == bases.MOTOR_PARAMS["R"]


def test_sweep_base(fuzz: Fuzz):
    args = ["sweep", "sweep.toml", "--out", "out", "--workers", "1", "--json"]
    summary = _accepted(fuzz, "sweep", args, {"sweep.toml": bases.SWEEP})
    assert summary["runs"] == 4
