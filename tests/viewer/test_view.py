"""`articula view` in a real headless Chromium: the arm renders, the slider moves it, the plots
are there; two tabs; closing the browser leaves the server up; Ctrl-C stops it; bad folders
and taken ports are one line, exit 2."""

from __future__ import annotations

import shutil
import signal
import socket
import urllib.request

import numpy as np
import pytest
import viser

from articula.viewer.replay import ERROR_FLOOR_MM, Replay
from tests.viewer.conftest import free_port, keep_screenshot, open_page, robot_mask, screenshot


def test_a_run_renders_and_the_slider_moves_the_arm(planned_run, viewer, browser, tmp_path):
    _, url = viewer("view", planned_run)
    page = open_page(browser, url)
    first = screenshot(page)
    assert first.std() > 10  # not a blank page
    arm = robot_mask(first)  # the 3-D view, left of the panel
    assert arm.sum() > 2000, arm.sum()
    assert page.locator(".uplot").count() == 2  # error and clearance plots
    time_box = page.locator("input[inputmode='decimal']:visible").first  # the slider's box
    time_box.fill("2.5")
    time_box.press("Enter")
    page.get_by_text("t = 2.50 s").wait_for(timeout=30_000)
    for _ in range(60):  # the arm's new pose follows the readout: wait until it is drawn
        moved = robot_mask(screenshot(page)) ^ arm
        if moved.sum() > 300:
            break
    assert moved.sum() > 300, moved.sum()  # the arm is elsewhere in the picture
    keep_screenshot(page, "view.png", tmp_path)


def test_two_tabs_and_a_closed_browser_leave_the_server_serving(planned_run, viewer, browser):
    proc, url = viewer("view", planned_run)
    pages = [open_page(browser, url) for _ in range(2)]
    for page in pages:
        assert robot_mask(screenshot(page)).sum() > 2000
    browser.close()
    assert proc.poll() is None
    with urllib.request.urlopen(url, timeout=10) as response:
        assert response.status == 200


def test_ctrl_c_stops_the_viewer(planned_run, viewer):
    proc, _ = viewer("view", planned_run)
    proc.send_signal(signal.SIGINT)
    assert proc.wait(15) == 130  # interrupted, as every command is
    assert "Traceback" not in proc.stderr.read()


def test_a_folder_without_a_run_is_one_line_and_exit_2(tmp_path, cli):
    proc = cli("view", tmp_path, "--port", str(free_port()))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "RUN_DIR" in proc.stderr


@pytest.mark.parametrize("damage", ["missing", "truncated"])
def test_a_run_without_its_whole_record_is_refused_in_one_line(planned_run, cli, tmp_path,
                                                               damage):  # fmt: skip
    run = tmp_path / "run"
    shutil.copytree(planned_run, run)
    record = run / "record.json"
    if damage == "missing":
        record.unlink()
    else:
        record.write_text(record.read_text()[:40])  # a write cut short
    proc = cli("view", run, "--port", str(free_port()))
    assert proc.returncode == 2 and "record.json" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_a_taken_port_is_one_line_and_exit_2(planned_run, cli):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        proc = cli("view", planned_run, "--port", str(port))
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "--port" in proc.stderr
    assert np.isfinite(port)


def test_plan_live_and_view_name_a_bad_key_alike(planned_run, cli, tmp_path):
    """One assembly (experiments.plan.build_plan): the same line, file and key, from each."""
    scene = tmp_path / "scene.toml"
    scene.write_text(
        (planned_run / "config.toml").read_text().replace("radius = 0.2", "radius = -0.2")
    )
    assert "radius = -0.2" in scene.read_text()
    run = tmp_path / "run"
    shutil.copytree(planned_run, run)
    shutil.copy(scene, run / "config.toml")
    plan = cli("plan", scene, "--out", tmp_path / "out")
    live = cli("live", scene, "--port", str(free_port()))
    assert plan.returncode == live.returncode == 2
    assert (
        plan.stderr
        == live.stderr
        == f"error: {scene}: trajectory.radius: Input should be greater than 0 (got -0.2)\n"
    )
    view = cli("view", run, "--port", str(free_port()))
    again = cli("plan", run / "config.toml", "--out", tmp_path / "out2")
    assert view.returncode == again.returncode == 2 and view.stderr == again.stderr
    assert f"{run / 'config.toml'}: trajectory.radius" in view.stderr


def test_the_error_is_plotted_on_a_log_axis_floored_at_a_micrometre(planned_run):
    server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    try:
        replay = Replay(server, [planned_run])
        error = replay.plots[0]
        assert error.scales["value"]["distr"] == 3 and error.scales["value"]["log"] == 10
        values = error.data[1]
        expected = np.maximum(1e3 * replay.run.error, ERROR_FLOOR_MM)  # mm, floored at 1 µm
        np.testing.assert_allclose(values, expected)
    finally:
        server.stop()
