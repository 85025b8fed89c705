"""`articula live`: an obstacle moved into the arm's way (through viser's server API, as a
drag does) changes the clearance the planner reports, which stays above d_min; the panel
rebuilds the controller; --record writes a run folder `view` replays with the moved obstacle;
the page renders in Chromium."""

from __future__ import annotations

import signal
import urllib.request

import numpy as np
import pyarrow.parquet as pq
import pytest
import tomli_w
import viser

from articula.scene import Obstacle, Scene
from articula.validation import load_toml
from articula.viewer.drawing import pose_of
from articula.viewer.live import READOUT_EVERY, Live, LiveScene
from articula.viewer.run_data import load_run
from tests.viewer.conftest import (
    CONFIGS,
    free_port,
    keep_screenshot,
    open_page,
    robot_mask,
    screenshot,
)


@pytest.fixture
def server():
    """A viser server on a free port, stopped after the test."""
    s = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    yield s
    s.stop()


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("method", ["qp", "baornn-improved"])
def test_an_obstacle_pushed_into_the_arm_is_avoided(server, scene_file, tmp_path, method):
    live = Live(server, LiveScene.load(scene_file, method))
    d_min = live.controller.planner.d_min
    for _ in range(100):  # 1 s along the circle
        live.period()
    before = live.recording.clearance[-1]
    # The rock dropped 4 cm ahead of the elbow, where the elbow is heading.
    robot, rock = live.scene.robot, live.gizmos["rock"]
    elbow = [robot.link_poses(q)["iiwa_link_4"][:3, 3] for q in live.recording.q[-2:]]
    heading = (elbow[1] - elbow[0]) / np.linalg.norm(elbow[1] - elbow[0])
    parts = live.scene.obstacles[0].parts
    for gap in np.arange(0.0, 0.5, 0.0025):
        T = pose_of(rock.wxyz, elbow[1] + gap * heading)
        if Scene(robot, [Obstacle("rock", parts, T)]).min_distance(live.q) >= 0.04:
            break
    rock.position = T[:3, 3]
    for _ in range(200):
        live.period()
    after = live.recording.clearance[100:]
    assert before - min(after) > 0.05  # the reported clearance follows the rock
    assert min(after) > d_min  # and the planner keeps out of its way
    assert live.painter.flush()
    assert "clearance" in live.readout.content
    assert live.painter.paint_ms  # the pictures went out on the painter's thread
    live.close()
    record = live.write(tmp_path / "rec", 1.0)
    assert record["metrics"]["collisions"] == 0
    replay = load_run(tmp_path / "rec")
    assert np.allclose(replay.obstacle_poses(len(replay.t) - 1)["rock"][:3, 3], rock.position,
                       atol=1e-6)  # fmt: skip
    assert replay.closest(len(replay.t) - 1).distance == pytest.approx(after[-1], abs=1e-6)


def test_the_panel_rebuilds_the_controller_and_refuses_a_start_within_d_min(server, scene_file):
    live = Live(server, LiveScene.load(scene_file, "qp"))
    for _ in range(5):
        live.period()
    live.method.value = "baornn-improved"
    live.rebuild()
    assert type(live.controller.planner).__name__ == "ImprovedBaornn"
    for _ in range(5):
        live.period()
    # The new controller took the arm's motion: the acceleration limit held across the switch.
    q = np.array(live.recording.q)
    acceleration = np.abs(np.diff(q, 2, axis=0)) / live.dt**2
    assert np.all(acceleration <= live.scene.robot.acceleration_limit * (1 + 1e-9))
    old, in_force = live.controller, live.d_min.value
    live.d_min.value = 5.0  # farther than any obstacle is (the panel's update rebuilds)
    assert live.controller is old and "not changed" in live.readout.content
    assert live.d_min.value == in_force  # the panel shows the setting in force
    for _ in range(3 * READOUT_EVERY):  # readouts go out: the refusal stays in them
        live.period()
    assert live.painter.flush()
    assert "not changed" in live.readout.content and "clearance" in live.readout.content
    live.d_min.value = in_force / 2  # the next change clears it
    for _ in range(READOUT_EVERY):
        live.period()
    assert live.painter.flush()
    assert "not changed" not in live.readout.content


@pytest.mark.slow
def test_the_live_page_renders_in_two_tabs_and_ctrl_c_writes_the_record(
    scene_file, viewer, browser, tmp_path
):
    proc, url = viewer("live", scene_file, "--method", "qp", "--record", tmp_path / "rec")
    pages = [open_page(browser, url, wait_for="clearance") for _ in range(2)]
    for page in pages:
        assert robot_mask(screenshot(page)).sum() > 2000
    keep_screenshot(pages[0], "live.png", tmp_path)
    browser.close()
    with urllib.request.urlopen(url, timeout=30) as response:  # the tabs went, it serves on
        assert response.status == 200
    assert proc.poll() is None
    proc.send_signal(signal.SIGINT)
    assert proc.wait(30) == 130
    run = load_run(tmp_path / "rec")
    assert len(run.t) > 10 and run.clearance.min() > 0


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    ("change", "field"),
    [({"d_min": -1.0}, "d_min"), ({"d_min": 5.0}, "d_min")],
    ids=["invalid", "cannot-start"],
)
def test_a_bad_scene_is_one_line_and_exit_2_before_any_server_opens(
    scene_file, tmp_path, cli, change, field
):
    config = load_toml(scene_file)
    config["planner"] |= change
    bad = tmp_path / "bad.toml"
    bad.write_text(tomli_w.dumps(config))
    proc = cli("live", bad, "--port", str(free_port()))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and field in proc.stderr
    assert "viser" not in proc.stdout + proc.stderr  # no server was opened


def test_the_readout_goes_out_with_a_picture():
    from articula.viewer.live import DRAW_EVERY, READOUT_EVERY

    assert READOUT_EVERY % DRAW_EVERY == 0  # else it shows only every lcm(...) periods


def test_a_start_in_collision_is_named_as_plan_names_it(main_fails, tmp_path):
    config = load_toml(CONFIGS / "circle_two_obstacles.toml")
    config["robot"] |= {"q0": [0.0, 1.9, 0.0, 2.0, 0.0, 2.0, 0.0], "self_collision": True}
    config["obstacles"] = []
    scene = tmp_path / "folded.toml"
    scene.write_text(tomli_w.dumps(config))
    line = main_fails("live", scene, "--port", "1")
    assert line.startswith(f"error: {scene}: robot.q0: the start collides with itself"), line


def test_the_panel_switches_a_baornn_scene_with_an_acceleration_limit_to_qp(server, tmp_path):
    config = load_toml(CONFIGS / "circle_one_obstacle.toml")
    config["obstacles"] = []
    config["planner"] |= {"method": "baornn-improved", "max_acceleration": 5.0}
    path = tmp_path / "scene.toml"
    path.write_text(tomli_w.dumps(config))
    live = Live(server, LiveScene.load(path))
    live.method.value = "qp"
    live.rebuild()
    assert "not changed" not in live.readout.content, live.readout.content
    assert live.spec().method == "qp"
    live.close()


@pytest.mark.parametrize("self_collision", [True, False])
def test_a_live_record_has_the_self_clearance_of_the_checked_pairs(
    server, scene_file, tmp_path, self_collision
):
    """Issue 48: live records said min_self_clearance: None. With self-collision on it is the
    smallest distance of the checked link pairs over the session (the scene's own, at each
    recorded q) and the trace has a self_clearance column; off, None as in plan's record."""
    config = load_toml(scene_file)
    config["robot"]["self_collision"] = self_collision
    scene_file.write_text(tomli_w.dumps(config))
    live = Live(server, LiveScene.load(scene_file, "qp"))
    for _ in range(20):
        live.period()
    live.close()
    record = live.write(tmp_path / "rec", 1.0)
    trace = pq.read_schema(tmp_path / "rec" / "trace.parquet").names
    scene = live.scene
    if not self_collision:
        assert not scene.self_pairs and record["metrics"]["min_self_clearance"] is None
        assert "self_clearance" not in trace
        return
    oracle = min(float(scene.self_distances(q).min()) for q in live.recording.q)
    assert record["metrics"]["min_self_clearance"] == pytest.approx(oracle, abs=1e-6)
    assert record["metrics"]["self_collisions"] == 0 and "self_clearance" in trace
