"""Fixtures of the viewer tests: a planned run, a free port, the viewer as a real process and
Debian's Chromium driven by Playwright."""

from __future__ import annotations

import io
import os
import shutil
import signal
import socket
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from articula.validation import load_toml

CHROMIUM_INSTALL = "apt-get install -y chromium"
CONFIGS = Path(__file__).resolve().parents[2] / "src/articula/book/ch1/configs"
SOFTWARE_GL_NOTICE = "#webgl-software-rendering"  # viser's "Software WebGL rendering detected"
ORANGE = np.array([255, 140, 0])  # viewer.drawing.ROBOT_COLOUR, shaded by the lights


@pytest.fixture(scope="session")
def chromium() -> str:
    """The path of Debian's Chromium (skip without it)."""
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    if path is None:
        pytest.skip(CHROMIUM_INSTALL)
    return path


@pytest.fixture(scope="session")
def planned_run(tmp_path_factory) -> Path:
    """A qp run of the book's two-obstacle circle, its approach from home and 3 s of the
    path, written by `articula plan`."""
    folder = tmp_path_factory.mktemp("view")
    config = load_toml(CONFIGS / "circle_two_obstacles.toml")
    for obstacle in config["obstacles"]:
        obstacle["mesh"] = str(CONFIGS / obstacle["mesh"])
    config["planner"] |= {"method": "qp", "duration": 3.0, "settle": 1.0}
    (folder / "scene.toml").write_text(tomli_w.dumps(config))
    articula = Path(sys.executable).parent / "articula"
    proc = subprocess.run([articula, "plan", folder / "scene.toml", "--out", folder / "run"],
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return folder / "run"


@pytest.fixture
def scene_file(tmp_path):
    """A live scene file: the book's circle beside the rock, its mesh by absolute path."""
    config = load_toml(CONFIGS / "circle_one_obstacle.toml")
    for obstacle in config["obstacles"]:
        obstacle["mesh"] = str(CONFIGS / obstacle["mesh"])
    path = tmp_path / "scene.toml"
    path.write_text(tomli_w.dumps(config))
    return path


def free_port() -> int:
    """A TCP port nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def viewer() -> Iterator[Callable[..., tuple[subprocess.Popen, str]]]:
    """viewer(*args) starts `articula <args> --port P` and reads its first line, the URL; (process,
    url). Every process started is stopped after the test."""
    started: list[subprocess.Popen] = []

    def start(*args: object) -> tuple[subprocess.Popen, str]:
        port = free_port()
        articula = Path(sys.executable).parent / "articula"
        command = [articula, *map(str, args), "--port", str(port)]
        proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        started.append(proc)
        assert proc.stdout is not None
        line = proc.stdout.readline()  # its URL line is all it prints (no viser banner)
        if f"http://127.0.0.1:{port} (Ctrl-C stops it)" in line:
            return proc, f"http://127.0.0.1:{port}"
        raise AssertionError(f"the viewer printed {line!r}, exit {proc.poll()}")

    yield start
    for proc in started:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()


@pytest.fixture
def browser(chromium):
    """A headless Chromium (software WebGL) under Playwright."""
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install -e '.[dev]'")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium, args=[
            "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader"])  # fmt: skip
        yield b
        if b.is_connected():
            b.close()


def open_page(browser, url: str, wait_for: str = "closest:"):
    """A 1280×800 tab on the viewer, connected and drawn (the panel shows `wait_for`)."""
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.goto(url)
    page.get_by_text("Connected").wait_for(timeout=60_000)
    page.get_by_text(wait_for).first.wait_for(timeout=60_000)
    page.add_style_tag(content=f"{SOFTWARE_GL_NOTICE} {{display: none}}")  # not in screenshots
    wait_for_frames(page, 30)  # software WebGL draws a few frames
    return page


def wait_for_frames(page, frames: int) -> None:
    """Return once the page has drawn `frames` more animation frames (an event the page
    signals, however slowly a loaded machine draws them)."""
    page.evaluate(
        """(count) => new Promise((done) => {
            const next = () => (--count <= 0 ? done() : requestAnimationFrame(next));
            requestAnimationFrame(next);
        })""",
        frames,
    )


def screenshot(page) -> np.ndarray:
    """The tab as an RGB array (rows, columns, 3), brought to the front first: Chromium does
    not draw a background tab (with two open, the first one's picture can be blank)."""
    from PIL import Image

    page.bring_to_front()
    wait_for_frames(page, 10)  # a few frames of software WebGL, once in front
    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)


def keep_screenshot(page, name: str, folder: Path) -> None:
    """Save the tab as folder/name, and also under $ARTICULA_SCREENSHOTS when that is set
    (`ARTICULA_SCREENSHOTS=docs/img pytest tests/viewer` refreshes the documentation's)."""
    png = page.screenshot()
    (folder / name).write_bytes(png)
    if os.environ.get("ARTICULA_SCREENSHOTS"):
        kept = Path(os.environ["ARTICULA_SCREENSHOTS"])
        kept.mkdir(parents=True, exist_ok=True)
        (kept / name).write_bytes(png)


def robot_mask(image: np.ndarray) -> np.ndarray:
    """Pixels of the robot in the 3-D view (left of the panel, right of the software-WebGL
    notice's orange bar): its orange, shaded toward red near obstacles, in any light: red
    high, green below it, blue low (the grey obstacles, green and blue paths and white
    background are not)."""
    view = image[:, 40:900]
    r, g, b = view[..., 0], view[..., 1], view[..., 2]
    return (r > 120) & (g < 0.8 * r) & (b < 0.35 * r)


os.environ.setdefault("PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD", "1")
