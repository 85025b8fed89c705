"""`articula live` driven from the real headless Chromium: the goal marker dragged with the
mouse switches the following off and the tool goes to it within the arm's limits; a refused
setting typed into the panel stays in the readout and the box goes back to the value in force.
The Live page runs in this process (its control loop on a thread), so the test reads the
controller's state while the browser acts on the page."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator

import numpy as np
import pytest
import viser

from articula.robots.sweep import joint_sweep
from articula.viewer.live import GOAL_GIZMO, READOUT_EVERY, Live, LiveScene
from tests.viewer.conftest import free_port, keep_screenshot, open_page

VIEWPORT = (1280, 800)  # open_page's tab: the canvas fills it


def wait_until(condition: Callable[[], bool], what: str, timeout: float = 60.0) -> None:
    """Return once condition() holds (checked as the loop runs), else fail naming `what`."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.01)  # polling a state, not waiting a fixed time for it


@pytest.fixture
def live_page(scene_file, browser) -> Iterator[tuple[Live, object]]:
    """(Live with qp on the one-obstacle circle, its loop running on a thread, a Chromium tab
    on it)."""
    server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    live = Live(server, LiveScene.load(scene_file, "qp"))
    stop = threading.Event()

    def loop() -> None:
        while not stop.is_set():
            live.period()
            stop.wait(live.dt)  # paces the simulated arm; nothing waits on it

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()
    page = open_page(browser, f"http://127.0.0.1:{server.get_port()}", wait_for="clearance")
    yield live, page
    stop.set()
    thread.join(30)
    live.close()
    server.stop()


def project(camera, point: np.ndarray) -> tuple[float, float]:
    """The pixel (x, y) of a world point [m] in the tab, by the client's own camera (three.js
    perspective: vertical field of view, the canvas's aspect)."""
    position, look_at = np.asarray(camera.position), np.asarray(camera.look_at)
    forward = (look_at - position) / np.linalg.norm(look_at - position)
    right = np.cross(forward, np.asarray(camera.up_direction))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    p = np.asarray(point) - position
    depth, half = p @ forward, np.tan(camera.fov / 2)
    x = (p @ right) / (depth * half * camera.aspect)
    y = (p @ up) / (depth * half)
    return (x + 1) / 2 * VIEWPORT[0], (1 - y) / 2 * VIEWPORT[1]


@pytest.mark.slow
def test_dragging_the_goal_marker_stops_the_following_and_the_tool_goes_there(live_page, tmp_path):
    live, page = live_page
    camera = next(iter(live.server.get_clients().values())).camera
    start = np.array(live.target.position)
    assert live.follow.value
    # Grab the marker's vertical (z) arrow partway up it, and pull it up by 60 px.
    arrow = GOAL_GIZMO * float(joint_sweep(live.scene.robot)[0])
    x, y = project(camera, start + np.array([0.0, 0.0, 0.15 * arrow]))
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x, y - 60, steps=12)
    page.mouse.up()
    wait_until(lambda: not live.follow.value, "the drag to switch the following off")
    goal = np.array(live.target.position)
    assert goal[2] - start[2] > 0.05 and np.linalg.norm(goal[:2] - start[:2]) < 0.01
    periods = live.periods

    def reached() -> bool:
        return np.linalg.norm(live.scene.robot.ee_position(live.q) - goal) < 1e-4

    wait_until(reached, "the tool to reach the goal")
    wait_until(lambda: live.periods > periods + READOUT_EVERY, "a readout after it")
    assert live.painter.flush()
    assert "goal error" in live.readout.content
    page.get_by_text("goal error").first.wait_for(timeout=30_000)
    keep_screenshot(page, "live_goal.png", tmp_path)
    # Within the arm's speed and acceleration limits all the while.
    q = np.array(live.recording.q[periods - 2 :])
    robot = live.scene.robot
    assert np.all(np.abs(np.diff(q, axis=0)) <= robot.velocity_limit * live.dt * (1 + 1e-9))
    acceleration = np.abs(np.diff(q, 2, axis=0)) / live.dt**2
    assert np.all(acceleration <= robot.acceleration_limit * (1 + 1e-9))


@pytest.mark.slow
def test_a_refused_setting_typed_in_stays_visible_and_the_box_shows_the_one_in_force(
    live_page,
):
    live, page = live_page
    in_force = float(live.d_min.value)
    box = page.get_by_label("d_min [m]")
    box.fill("5")  # farther than any obstacle is: a start the controller refuses
    box.press("Enter")
    page.get_by_text("not changed").first.wait_for(timeout=30_000)
    wait_until(lambda: live.refusal is not None, "the refusal")
    periods = live.periods
    wait_until(lambda: live.periods > periods + 3 * READOUT_EVERY, "readouts after it")
    assert live.painter.flush()
    page.get_by_text("not changed").first.wait_for(timeout=30_000)  # still there
    assert page.get_by_text("clearance").first.is_visible()
    wait_until(lambda: box.input_value() == f"{in_force:g}", "the box to go back")
    assert float(live.d_min.value) == in_force
