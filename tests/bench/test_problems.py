"""bench/problems.py: generated problems are reproducible, start clear, keep their obstacles off
the path and beside the arm, and are scene files `articula plan` runs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from articula.bench import problems
from articula.loops.tracking import track
from articula.planning.config import TrajectorySpec, make_targets
from articula.planning.velocity_ik import VelocityIk
from articula.scene.config import build_scene, load_scene_spec
from articula.scene.scene import Scene

IIWA = {"builtin": "iiwa14"}


@pytest.fixture(scope="module")
def generated() -> list[problems.Problem]:
    """Problems 0-5 of seed 3 for the iiwa."""
    return [problems.generate(IIWA, 3, i) for i in range(6)]


def _scene(problem: problems.Problem, folder: Path):
    """The problem's scene, q0 and path targets, its meshes written to `folder`."""
    for name, mesh in problem.meshes.items():
        (folder / name).write_bytes(mesh.export(file_type="stl"))
    scene, q0 = build_scene(load_scene_spec(problem.config), folder)
    return scene, q0, make_targets(TrajectorySpec(**problem.config["trajectory"]), folder)


def test_the_same_seed_and_index_give_the_same_problem(generated):
    again = problems.generate(IIWA, 3, 2)
    assert json.dumps(again.config) == json.dumps(generated[2].config)
    assert json.dumps(problems.generate(IIWA, 4, 2).config) != json.dumps(again.config)


def test_the_start_is_clear_and_the_path_begins_at_the_end_effector(generated, tmp_path):
    for problem in generated:
        scene, q0, targets = _scene(problem, tmp_path)
        assert scene.clearances(q0)[0] > problems.START_CLEARANCE
        assert np.allclose(targets(0.0).position, scene.robot.ee_position(q0), atol=1e-9)
        assert np.all(q0 >= scene.robot.lower) and np.all(q0 <= scene.robot.upper)
        assert 1 <= len(scene.obstacles) <= 4


@pytest.mark.slow
def test_obstacles_keep_off_the_path_but_come_near_the_arm(generated, tmp_path):
    near = 0
    for problem in generated:
        scene, q0, targets = _scene(problem, tmp_path)
        duration = problem.config["planner"]["duration"]
        path = np.array([targets(t).position for t in np.arange(0.0, duration, 0.05)])
        for obstacle in scene.obstacles:
            vertices = obstacle.parts[0].vertices
            centre = obstacle.pose_at(0.0)[:3, 3]
            radius = np.max(np.linalg.norm(vertices, axis=1))
            assert np.min(np.linalg.norm(path - centre, axis=1)) - radius >= problems.PATH_CLEARANCE
        near += scene.clearances(q0)[0] < problems.INFLUENCE
    assert near >= 2  # obstacles sit where the arm is, not anywhere in the workspace


@pytest.mark.slow
def test_a_problem_file_runs_with_articula_plan(generated, tmp_path, cli, one_json):
    problem = generated[0]
    for name, mesh in problem.meshes.items():
        (tmp_path / name).write_bytes(mesh.export(file_type="stl"))
    config = {**problem.config, "planner": {**problem.config["planner"], "method": "qp"}}
    (tmp_path / "scene.toml").write_text(tomli_w.dumps(config))
    proc = cli("plan", tmp_path / "scene.toml", "--out", tmp_path / "run", "--json")
    assert proc.returncode == 0, proc.stderr
    metrics = one_json(proc.stdout)["metrics"]
    assert metrics["min_clearance"] > 0 and metrics["max_speed_ratio"] <= 1.0 + 1e-9


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    ("problem_class", "count", "gap"),
    [("tight", (2, 4), problems.TIGHT_GAP), ("grazing", (1, 2), problems.GRAZING_GAP)],
)
def test_each_obstacle_sits_its_class_gap_from_the_obstacle_free_motion(
    tmp_path, problem_class, count, gap
):
    # tight: 2-5 cm from the links; grazing: the links pass within d_min of it (or into it).
    for index in range(3):
        problem = problems.generate(IIWA, 3, index, problem_class)
        scene, q0, targets = _scene(problem, tmp_path)
        duration = problem.config["planner"]["duration"]
        # The obstacle-free motion again: damped least squares along the path.
        planner = VelocityIk(Scene(scene.robot, []), "dls", problems.DT)
        motion = track(planner, targets, q0, problems.DT, duration, 10**6).q
        assert count[0] <= len(scene.obstacles) <= count[1]
        for obstacle in scene.obstacles:
            alone = Scene(scene.robot, [obstacle])
            closest = min(alone.clearances(q)[0] for q in motion)
            assert gap[0] - 1e-9 <= closest <= gap[1] + 1e-9
            if problem_class == "grazing":
                assert closest <= problems.D_MIN  # the free motion breaks d_min
