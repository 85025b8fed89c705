"""`articula plan`: the run folder contract and its bad-input paths."""

from __future__ import annotations

import json
from pathlib import Path

import pyarrow.parquet as pq
import pytest

CONFIGS = Path(__file__).resolve().parents[1] / "src/articula/experiments/configs/ch1"

SCENE = """
[robot]
builtin = "iiwa14"
q0 = [0, 0, 0, 0, 0, 0, 0]

[[obstacles]]
name = "ball"
sphere = 0.08
position = [0.35, 0.35, 0.6]

[trajectory]
{trajectory}

[planner]
method = "{method}"
lambda_weight = 0.002
d_min = 0.002
duration = 1.0
settle = 0.5
seed = 0
"""
CIRCLE = """type = "circle"
center = [0.0, 0.6, 0.5]
axis_a = [1.0, 0.0, 0.0]
axis_b = [0.0, 0.0, 1.0]
radius = 0.2
period = 50.0"""


def _scene(tmp_path: Path, trajectory: str = CIRCLE, method: str = "baornn") -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.format(trajectory=trajectory, method=method))
    return path


def test_plan_writes_the_run_folder_contract(cli, tmp_path):
    out = tmp_path / "run"
    proc = cli("plan", _scene(tmp_path), "--out", out, "--json")
    assert proc.returncode == 0, proc.stderr
    record = json.loads(proc.stdout)
    keys = {"rms_error", "max_error", "min_clearance", "collisions", "joint_limit_violations",
            "time_per_iteration_us", "settle_s"}  # fmt: skip
    assert keys <= set(record["metrics"])
    assert json.loads((out / "record.json").read_text()) == record
    table = pq.read_table(out / "trace.parquet")
    columns = ["t", *[f"q_{j}" for j in range(1, 8)], "x", "y", "z", "x_ref", "y_ref", "z_ref",
               "error", "clearance"]  # fmt: skip
    assert table.column_names == columns
    assert table.num_rows == 100
    assert record["metrics"]["collisions"] == 0 and record["metrics"]["joint_limit_violations"] == 0


def test_same_scene_same_numbers(cli, tmp_path):
    scene = _scene(tmp_path)
    a = json.loads(cli("plan", scene, "--out", tmp_path / "a", "--json").stdout)
    b = json.loads(cli("plan", scene, "--out", tmp_path / "b", "--json").stdout)
    assert a["metrics"]["rms_error"] == b["metrics"]["rms_error"]
    ta = pq.read_table(tmp_path / "a" / "trace.parquet").drop(["t"])
    assert ta.equals(pq.read_table(tmp_path / "b" / "trace.parquet").drop(["t"]))


@pytest.mark.parametrize(
    ("trajectory", "method", "field"),
    [
        (CIRCLE, "magic", "method"),
        ('type = "circle"\nradius = 0.2', "baornn", "center"),
        (
            'type = "waypoints"\npoints = [[0, 0.6, 0.5], [0.1, 0.6, 0.5]]\ntimes = [1.0, 1.0]',
            "baornn",
            "times",
        ),
        ('type = "csv"\npath = "missing.csv"', "baornn", "missing.csv"),
    ],
    ids=["unknown_method", "circle_without_center", "non_increasing_times", "missing_csv"],
)
def test_bad_plans_are_one_line_and_write_nothing(
    cli, tmp_path, assert_one_line_error, trajectory, method, field
):
    out = tmp_path / "run"
    proc = cli("plan", _scene(tmp_path, trajectory, method), "--out", out, "--json")
    assert proc.stdout == ""
    assert_one_line_error(proc, field)
    assert not out.exists()


def test_a_start_inside_the_obstacle_is_refused(cli, tmp_path, assert_one_line_error):
    text = SCENE.format(trajectory=CIRCLE, method="baornn").replace(
        "position = [0.35, 0.35, 0.6]", "position = [0.0, 0.0, 1.0]"
    )
    path = tmp_path / "scene.toml"
    path.write_text(text)
    proc = cli("plan", path, "--out", tmp_path / "run", "--json")
    assert_one_line_error(proc, "q0")
    assert not (tmp_path / "run").exists()
