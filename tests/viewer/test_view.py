"""`articula view` in a real headless Chromium: the arm renders, the slider moves it and the
plots' time cursor with it, the trail draws the arm along the run; two tabs; closing the
browser leaves the server up; Ctrl-C stops it; bad folders and taken ports are one line,
exit 2."""

from __future__ import annotations

import shutil
import signal
import socket
import urllib.request

import numpy as np
import pytest
import viser

from articula.viewer.replay import ERROR_FLOOR_MM, TRAIL_POSES, Replay
from articula.viewer.run_data import load_run
from articula.viewer.time_plot import CURSOR_COLOUR, thinned
from tests.viewer.conftest import free_port, keep_screenshot, open_page, robot_mask, screenshot

CURSOR_RGB = np.array([int(CURSOR_COLOUR[i : i + 2], 16) for i in (1, 3, 5)])


def ghost_mask(image: np.ndarray) -> np.ndarray:
    """Pixels of a see-through orange arm over the white background (the trail's): pale,
    red above green above blue, in the 3-D view."""
    view = image[:, 40:900]
    r, g, b = view[..., 0], view[..., 1], view[..., 2]
    return (r > 200) & (g >= 0.8 * r) & (g < 0.97 * r) & (b < 0.92 * g)


def cursor_column(page) -> float:
    """The mean pixel column of the time cursor's blue in the first plot (nan: none)."""
    box = page.locator(".uplot").first.bounding_box()
    image = screenshot(page)
    plot = image[int(box["y"]) : int(box["y"] + box["height"]),
                 int(box["x"]) : int(box["x"] + box["width"])]  # fmt: skip
    columns = np.nonzero(np.abs(plot - CURSOR_RGB).max(axis=2) < 40)[1]
    return float(columns.mean()) if columns.size > 20 else float("nan")


def test_a_run_renders_and_the_slider_moves_the_arm(planned_run, viewer, browser, tmp_path):
    _, url = viewer("view", planned_run)
    page = open_page(browser, url)
    first = screenshot(page)
    assert first.std() > 10  # not a blank page
    arm = robot_mask(first)  # the 3-D view, left of the panel
    assert arm.sum() > 2000, arm.sum()
    assert page.locator(".uplot").count() == 2  # error and clearance plots
    before = cursor_column(page)
    assert np.isfinite(before)  # the cursor at t = 0
    time_box = page.locator("input[inputmode='decimal']:visible").first  # the slider's box
    time_box.fill("6")
    time_box.press("Enter")
    page.get_by_text("t = 6.00 s").wait_for(timeout=30_000)
    for _ in range(60):  # the arm's new pose follows the readout: wait until it is drawn
        moved = robot_mask(screenshot(page)) ^ arm
        if moved.sum() > 300:
            break
    assert moved.sum() > 300, moved.sum()  # the arm is elsewhere in the picture
    for _ in range(60):  # and the plots' cursor, drawn as the new data comes
        after = cursor_column(page)
        if after > before + 20:
            break
    assert after > before + 20, (before, after)  # the cursor moved right with the time
    keep_screenshot(page, "view.png", tmp_path)
    pale = ghost_mask(screenshot(page)).sum()
    page.get_by_label("trail").check()
    for _ in range(60):  # the trail's see-through arms: pale orange along the run
        trail = ghost_mask(screenshot(page)).sum()
        if trail > pale + 3000:
            break
    assert trail > pale + 3000, (pale, trail)
    keep_screenshot(page, "view_trail.png", tmp_path)


def test_a_time_typed_beyond_the_run_is_put_back_in_the_box(planned_run, viewer, browser):
    """Issue 48: the box kept a time typed beyond the run (999) while the arm showed its end."""
    sync_api = pytest.importorskip("playwright.sync_api")
    _, url = viewer("view", planned_run)
    page = open_page(browser, url)
    end = float(load_run(planned_run).t[-1])
    time_box = page.locator("input[inputmode='decimal']:visible").first  # the slider's box
    for typed, shown in (("999", end), ("-5", 0.0)):
        time_box.fill(typed)
        time_box.press("Enter")  # still focused: the box shows what the server sends back
        sync_api.expect(time_box).not_to_have_value(typed, timeout=30_000)
        assert float(time_box.input_value()) == pytest.approx(shown, abs=1e-6)
        page.get_by_text(f"t = {shown:.2f} s").wait_for(timeout=30_000)


@pytest.mark.slow
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


@pytest.mark.slow_cases(keep=1)
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


@pytest.mark.slow
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
        scale = error.handle.scales["value"]
        assert scale["distr"] == 3 and scale["log"] == 10
        expected = np.maximum(1e3 * replay.run.error, ERROR_FLOOR_MM)  # mm, floored at 1 µm
        np.testing.assert_allclose(error.values, thinned(replay.run.t, expected)[1])
    finally:
        server.stop()


def test_thinning_keeps_every_peak_and_the_cursor_follows_the_scene(planned_run):
    t = np.linspace(0.0, 10.0, 5001)
    values = np.sin(7 * t) + (t > 6.1234) * 3.0  # a step the thinning must keep
    kept_t, kept = thinned(t, values, 400)
    assert len(kept_t) <= 400 and np.all(np.diff(kept_t) >= 0)
    assert kept.max() == values.max() and kept.min() == values.min()
    server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    try:
        replay = Replay(server, [planned_run])
        k = len(replay.run.t) // 2
        replay.show(k)
        for plot in replay.plots:
            t_plot, _, cursor = plot.handle.data
            line = np.isfinite(cursor)
            assert line.sum() == 2 and set(cursor[line]) == {0.0, 1.0}  # bottom to top
            assert np.all(t_plot[line] == plot.cursor)
            assert plot.cursor <= replay.run.t[k] < plot.cursor + 0.2  # the sample at or before
        replay.trail.value = True
        assert len(replay.ghosts) == TRAIL_POSES * len(replay.run.visuals)
        replay.trail.value = False
        assert replay.ghosts == []
    finally:
        server.stop()
