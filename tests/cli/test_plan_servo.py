"""`articula plan --servo-rate`: servo.parquet, the record's limits, and its bad-input paths;
a run folder whose record lists a table that is missing is not finished."""

from __future__ import annotations

import json

import numpy as np
import pyarrow.parquet as pq
import pytest

from articula.runs.records import is_finished
from tests.cli.test_plan import CIRCLE, SCENE

# The test scene with [planner] limits left at its default (--servo-rate then keeps the jerk
# limits, as a stream needs) and its tolerance lifted: within those limits the arm does not
# reach the path, which starts away from it, in the run's one second.
STREAMED = SCENE.replace('limits = "none"\n', "tolerance = 10.0\n")


def test_a_servo_rate_writes_the_stream_and_the_limits(cli, tmp_path, one_json):
    scene = tmp_path / "scene.toml"
    scene.write_text(STREAMED.format(trajectory=CIRCLE, method="qp"))
    out = tmp_path / "run"
    proc = cli("plan", scene, "--out", out, "--servo-rate", "500", "--json")
    assert proc.returncode == 0, proc.stderr
    record = one_json(proc.stdout)
    assert record["tables"] == ["servo.parquet"]
    limits = record["limits"]  # the iiwa14's, from its URDF and the default rules
    assert set(limits) == {"velocity", "acceleration", "jerk", "sources", "datasheet"}
    assert all(len(limits[k]) == 7 for k in ("velocity", "acceleration", "jerk"))
    assert limits["datasheet"] is None
    assert limits["sources"] == {
        "velocity": ["urdf"] * 7,
        "acceleration": ["default rule (accel_time = 0.25 s)"] * 7,
        "jerk": ["default rule (jerk_time = 0.01 s)"] * 7,
    }
    m = record["metrics"]
    assert m["servo_rate_hz"] == 500 and m["servo_max_jerk_ratio"] <= 1 + 1e-6
    assert m["max_jerk_ratio"] <= 1 + 1e-6
    servo = pq.read_table(out / "servo.parquet").to_pydict()
    assert {"t", "q_1", "q_7", "qd_1", "qdd_7"} <= set(servo)
    assert np.diff(servo["t"])[0] == np.float64(1 / 500)
    config = (out / "config.toml").read_text()
    assert "[servo]" in config and 'limits = "velocity+acceleration+jerk"' in config
    assert is_finished(out)
    (out / "servo.parquet").unlink()
    assert not is_finished(out)  # the record lists it: the run is recomputed on resume
    proc = cli("plan", scene, "--out", out)  # the same folder, no stream this time
    assert proc.returncode == 0, proc.stderr
    record = json.loads((out / "record.json").read_text())
    assert "tables" not in record and not (out / "servo.parquet").exists()
    line = " ".join(proc.stdout.split())  # rich wraps to the terminal width
    assert f"max {1e3 * record['metrics']['max_error']:.3f} mm" in line
    assert "servo at" not in line and "twin:" not in line  # only what the record has


@pytest.mark.slow
def test_the_line_gives_the_streams_acceleration_and_jerk_ratios(cli, tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(STREAMED.format(trajectory=CIRCLE, method="qp"))
    out = tmp_path / "run"
    proc = cli("plan", scene, "--out", out, "--servo-rate", "1000")
    assert proc.returncode == 0, proc.stderr
    m = json.loads((out / "record.json").read_text())["metrics"]
    line = " ".join(proc.stdout.split())
    assert (
        f"servo at {m['servo_max_acceleration_ratio']:.2f} of the acceleration and "
        f"{m['servo_max_jerk_ratio']:.2f} of the jerk limits, "
        f"{m['servo_max_velocity_ratio']:.2f} of the speed limits, "
        f"{int(m['servo_clipped'])} set-points clipped" in line  # issue 48: all of the stream's
    )
    assert "twin:" not in line


def test_a_servo_rate_that_does_not_divide_the_period_is_one_line(
    cli, tmp_path, assert_one_line_error
):
    scene = tmp_path / "scene.toml"
    scene.write_text(STREAMED.format(trajectory=CIRCLE, method="qp"))
    proc = cli("plan", scene, "--out", tmp_path / "run", "--servo-rate", "333")
    assert_one_line_error(proc, "servo.rate", "scene.toml")
    assert not (tmp_path / "run").exists()


@pytest.mark.slow
def test_a_servo_stream_without_the_jerk_limits_is_one_line(cli, tmp_path, assert_one_line_error):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.format(trajectory=CIRCLE, method="qp"))  # limits = "none"
    proc = cli("plan", scene, "--out", tmp_path / "run", "--servo-rate", "1000")
    assert_one_line_error(proc, "planner.limits", "velocity+acceleration+jerk")


@pytest.mark.slow
def test_a_stream_too_long_to_hold_is_refused_before_the_run(cli, tmp_path, assert_one_line_error):
    scene = tmp_path / "scene.toml"
    limited = "[servo]\nrate = 1000\nmax_samples = 5000\n"  # 1 s of plan at 1 kHz: 1000
    scene.write_text(STREAMED.format(trajectory=CIRCLE, method="qp") + limited)
    proc = cli("plan", scene, "--out", tmp_path / "run", "--servo-rate", "10000")  # 10000
    assert_one_line_error(proc, "servo.max_samples")
    assert not (tmp_path / "run").exists()
