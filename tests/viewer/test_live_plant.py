"""`articula live --plant mujoco`: the page's commands drive the MuJoCo twin through the servo
stream, the controller closes its loop on the measured joints, the measured arm is drawn where
the twin has it (and its obstacles where the page's gizmos put them), --record keeps the twin's
columns and metrics (a session stopped by a signal anywhere in a period too), and the page
renders in Chromium."""

from __future__ import annotations

import os
import signal
import sys

import numpy as np
import pyarrow.parquet as pq
import pytest
import tomli_w
import viser

from articula.signals import Interrupted, Terminated, terminate_as_interrupt
from articula.viewer.drawing import wxyz_position
from articula.viewer.live import Live, LiveScene
from articula.viewer.run_data import load_run
from tests.arms import JACO2_HOME, arm_scene
from tests.viewer.conftest import free_port, keep_screenshot, open_page, screenshot

mujoco = pytest.importorskip(
    "mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"'
)


@pytest.fixture
def server():
    """A viser server on a free port, stopped after the test."""
    s = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    yield s
    s.stop()


def test_the_measured_arm_follows_the_commands_and_is_drawn_where_the_twin_has_it(
    server,
    scene_file,
    tmp_path,
):
    live = Live(server, LiveScene.load(scene_file, "qp", plant="mujoco"))
    assert live.spec().limits == "velocity+acceleration+jerk"  # a stream's, as plan's
    rock = live.gizmos["rock"]
    for k in range(150):
        if k == 100:  # the rock dragged 5 cm up: the twin's copy goes with it
            rock.position = np.add(rock.position, [0.0, 0.0, 0.05])
        live.period()
    twin = live.plant.arm.twin
    mocap = twin.model.body("moving_0").mocapid[0]
    np.testing.assert_allclose(twin.data.mocap_pos[mocap], rock.position, atol=1e-9)
    commanded, measured = np.array(live.recording.q), np.array(live.plant.arm.measured)
    assert len(measured) == 150
    assert np.max(np.abs(commanded - measured)[50:]) < 0.02  # the servo follows within 20 mrad
    assert not any(live.plant.arm.contacts) and min(live.recording.measured_clearance) > 0
    assert live.painter.flush()
    assert "measured: error" in live.readout.content
    poses = live.scene.robot.link_poses(live.plant.q)
    for name, frame in live.plant.frames.items():
        if name in poses:
            np.testing.assert_allclose(frame.position, wxyz_position(poses[name])[1], atol=1e-6)
    live.close()
    record = live.write(tmp_path / "rec", 1.0)
    assert record["metrics"]["plant_contacts"] == 0
    assert record["metrics"]["plant_min_clearance"] == min(live.recording.measured_clearance)
    assert 0 < record["metrics"]["max_torque_ratio"] <= 1
    assert len(load_run(tmp_path / "rec").t) == 150


@pytest.mark.slow
def test_a_jaco_at_its_unwrapped_home_drives_the_twin_as_from_the_wrapped_pose(server, tmp_path):
    """Kinova's home reads 4.80 and 4.20 rad on the continuous joints 1 and 4: the twin starts
    at the wrapped pose and follows the commands the short way, as from the pose written
    wrapped."""
    wrapped = [x - 2 * np.pi if j in (0, 3) else x for j, x in enumerate(JACO2_HOME)]
    tools, robot = [], None
    for k, q0 in enumerate((JACO2_HOME, wrapped)):
        data = arm_scene("jaco2", duration=6.0)
        data["robot"]["q0"] = q0
        path = tmp_path / f"jaco{k}.toml"
        path.write_text(tomli_w.dumps(data))
        live = Live(server, LiveScene.load(path, "qp", plant="mujoco"))
        for _ in range(200):
            live.period()
        robot = live.scene.robot
        commanded, measured = np.array(live.recording.q), np.array(live.plant.arm.measured)
        lag = robot.difference(measured, commanded)[:, robot.continuous]
        assert np.max(np.abs(lag)) < 0.02  # [rad] the short way, never a turn behind
        assert np.all(np.abs(measured[:, robot.continuous]) <= np.pi)  # handed back wrapped
        tools.append(np.array([robot.ee_position(q) for q in measured]))
        live.close()
    assert robot.continuous.tolist() == [True, False, False, True, False, True]
    np.testing.assert_allclose(tools[0], tools[1], atol=5e-5)  # [m]


def test_an_unknown_plant_is_one_line_and_exit_2(scene_file, cli):
    proc = cli("live", scene_file, "--plant", "gazebo", "--port", str(free_port()))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "--plant" in proc.stderr


@pytest.mark.slow
def test_the_live_page_shows_the_measured_arm(scene_file, viewer, browser, tmp_path):
    proc, url = viewer("live", scene_file, "--method", "qp", "--plant", "mujoco")
    page = open_page(browser, url, wait_for="measured: error")
    view = screenshot(page)[:, 40:900]  # the 3-D view, as robot_mask takes it
    keep_screenshot(page, "live_plant.png", tmp_path)
    r, g, b = view[..., 0], view[..., 1], view[..., 2]
    assert np.sum((b > 120) & (b > 1.3 * r) & (b > 1.1 * g)) > 2000  # the measured arm's blue
    proc.send_signal(signal.SIGINT)
    assert proc.wait(30) == 130


def signal_at(event: int, signum: int):
    """A trace function that sends this process `signum` at the `event`-th Python trace event
    (a call or a line), where a real signal would land; None: only counts them."""
    seen = 0

    def trace(frame, kind, arg):
        nonlocal seen
        seen += 1
        if seen == event:
            os.kill(os.getpid(), signum)
        return trace

    trace.seen = lambda: seen
    return trace


def test_a_session_stopped_by_a_signal_anywhere_in_a_period_is_written_whole(
    server, scene_file, tmp_path
):
    """Issue 48: a signal between a period's measured row and its reference row lost the
    session (ValueError: shapes (6400,3) (6399,3)). SIGINT or SIGTERM at 20 seeded points of
    a period: every record is readable, its columns one row per whole period."""
    loaded = LiveScene.load(scene_file, "qp", plant="mujoco")
    live = Live(server, loaded)
    live.period()
    counter, previous = signal_at(0, signal.SIGINT), sys.gettrace()
    sys.settrace(counter)
    try:
        live.period()
    finally:
        sys.settrace(previous)
    live.close()
    rng = np.random.default_rng(48)
    for trial in range(20):
        live = Live(server, loaded)
        for _ in range(3):
            live.period()
        signum = [signal.SIGINT, signal.SIGTERM][trial % 2]
        trace = signal_at(int(rng.integers(1, counter.seen())), signum)
        with pytest.raises((Interrupted, Terminated)), terminate_as_interrupt():
            sys.settrace(trace)  # here: only the periods' events count
            try:
                live.period()
                live.period()  # the signal lands before the next bytecode, at the latest
            finally:
                sys.settrace(previous)
        live.close()
        record = live.write(tmp_path / f"rec{trial}", 1.0)
        run = load_run(tmp_path / f"rec{trial}")
        assert len(run.t) in (3, 4) and len(live.plant.arm.measured) == len(run.t)
        assert np.isfinite(record["metrics"]["plant_rms_error"])


def test_sigterm_writes_the_record_of_a_live_session_with_the_twin(scene_file, viewer, tmp_path):
    proc, _ = viewer("live", scene_file, "--method", "qp", "--plant", "mujoco", "--record",
                     tmp_path / "rec")  # fmt: skip
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(60) == 143, proc.stderr.read()
    assert len(load_run(tmp_path / "rec").t) >= 1
    assert "qm_1" in pq.read_schema(tmp_path / "rec" / "trace.parquet").names
