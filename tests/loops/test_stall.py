"""loops/stall.py: a run that stood still off its path says how long, where and at which pair;
one that kept moving, or one whose tolerance is tighter than it tracks, says that instead."""

from __future__ import annotations

import numpy as np
import pytest
import tomli_w

from articula.bench import problems
from articula.experiments.plan import PlanConfig, load_plan, run_plan
from articula.loops.stall import STALL_SPEED, standing_still
from articula.planning import resolved_rate
from articula.robots import RobotModel
from articula.validation import parse_model

ROBOT = RobotModel.builtin("iiwa14")
DT = 0.01


def test_standing_still_is_every_joint_under_a_hundredth_of_its_speed_limit():
    q0 = np.zeros(ROBOT.nq)
    creep = 0.5 * STALL_SPEED * ROBOT.velocity_limit * DT  # per period, every joint
    q = np.cumsum(np.tile(creep, (4, 1)), axis=0)
    q[2, 3] += 2 * STALL_SPEED * ROBOT.velocity_limit[3] * DT  # one joint moves on period 2
    assert standing_still(ROBOT, q, q0, DT).tolist() == [True, True, False, False]
    assert standing_still(ROBOT, q, None, DT)[0] == np.False_  # no start: it counts as moving


@pytest.fixture
def grazing_config(tmp_path, monkeypatch):
    """Grazing problem 1 of seed 0 (bench/problems.py) as a plan config for pinv with a 1 mm
    tolerance, its meshes in tmp_path (the working folder)."""
    problem = problems.generate({"builtin": "iiwa14"}, 0, 1, "grazing")
    for name, mesh in problem.meshes.items():
        (tmp_path / name).write_bytes(mesh.export(file_type="stl"))
    config = {**problem.config}
    config["planner"] = {**config["planner"], "method": "pinv", "tolerance": 0.001}
    (tmp_path / "scene.toml").write_text(tomli_w.dumps(config))
    monkeypatch.chdir(tmp_path)
    data = load_plan(tmp_path / "scene.toml")
    data.pop("experiment", None)
    return parse_model(PlanConfig, data, "scene")


def test_a_run_frozen_at_d_min_names_the_stall_its_pair_and_distance(grazing_config, monkeypatch):
    monkeypatch.setattr(resolved_rate, "SLIDES", 0)  # the step check alone: the arm freezes
    result = run_plan(grazing_config)
    m = result.metrics
    assert m["tracked"] is False
    assert m["stalled_s"] > 1.0
    obstacles = [o["name"] for o in grazing_config.model_dump()["obstacles"]]
    assert m["stall_pair"].split(" / ")[1] in obstacles  # a link and the problem's obstacle
    assert m["stall_clearance"] == pytest.approx(problems.D_MIN, abs=1e-5)
    why = result.details["not_tracked"]
    assert "stalled" in why and "clearance boundary" in why and m["stall_pair"] in why
    assert f"{1e3 * m['stall_clearance']:.2f} mm" in why


def test_the_same_run_with_the_slide_tracks_and_never_stalls(grazing_config):
    result = run_plan(grazing_config)
    m = result.metrics
    assert m["tracked"] is True and "not_tracked" not in result.details
    assert m["stalled_s"] == 0.0 and m["stall_pair"] is None
    assert m["min_clearance"] >= problems.D_MIN
