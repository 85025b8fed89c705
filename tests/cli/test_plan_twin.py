"""`articula plan` with `[plant] type = "mujoco"`: a ball drifts onto the arm; the plan steps
aside, and so does the stiff default twin, but a twin whose servos are too soft to follow is
hit: MuJoCo's contacts exit 4 like a planned collision, with the run folder written."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"')

SCENE = """
[robot]
builtin = "iiwa14"
q0 = [0, 0.5, 0, -1.2, 0, 0.8, 0]

[[obstacles]]
name = "ball"
sphere = 0.06
position = [0.67, 0.6, 0.58]
velocity = [0.0, -0.1, 0.0]

[trajectory]
type = "waypoints"
points = [[0.673, 0.0, 0.576], [0.673, 0.0, 0.576]]
times = [0.0, 9.0]

[planner]
method = "qp"
d_min = 0.01
duration = 8.0
settle = 1.0
tolerance = 10.0

[servo]
rate = 1000

[plant]
type = "mujoco"
{stiffness}
"""


def _plan(cli, tmp_path, stiffness: str, *options: str):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.format(stiffness=stiffness))
    out = tmp_path / "run"
    return cli("plan", scene, "--out", out, *options), out


@pytest.mark.slow
def test_a_stiff_twin_steps_aside_with_the_plan_and_the_line_says_how_it_tracked(cli, tmp_path):
    proc, out = _plan(cli, tmp_path, "")
    assert proc.returncode == 0, proc.stderr
    m = json.loads((out / "record.json").read_text())["metrics"]
    assert m["collisions"] == 0 and m["plant_contacts"] == 0
    assert m["plant_min_clearance"] > 0.005
    line = " ".join(proc.stdout.split())  # rich wraps to the terminal width
    assert f"max {1e3 * m['max_error']:.3f} mm" in line
    assert (
        f"servo at {m['servo_max_acceleration_ratio']:.2f} of the acceleration and "
        f"{m['servo_max_jerk_ratio']:.2f} of the jerk limits, "
        f"{m['servo_max_velocity_ratio']:.2f} of the speed limits, "
        f"{int(m['servo_clipped'])} set-points clipped" in line  # issue 48: all of the stream's
    )
    assert (
        f"twin: RMS error {1e3 * m['plant_rms_error']:.3f} mm, torque at "
        f"{m['max_torque_ratio']:.2f} of the effort limits, contacts in 0 periods" in line
    )


def test_a_twin_too_soft_to_follow_is_hit_and_exits_4(cli, tmp_path):
    proc, out = _plan(cli, tmp_path, "stiffness = 0.01", "--json")
    assert proc.returncode == 4, proc.stderr
    assert "twin" in proc.stderr and len(proc.stderr.splitlines()) == 1
    m = json.loads(proc.stdout)["metrics"]
    assert m["collisions"] == 0  # the plan itself keeps clear
    assert m["plant_contacts"] > 0 and m["plant_min_clearance"] < 0.0  # coal agrees
    assert (out / "record.json").exists() and (out / "servo.parquet").exists()
