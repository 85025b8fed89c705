"""Real-time budget of `articula live` (issue 14): one control period with its page update.

    python benchmarks/viewer.py [--json] [--periods N]

The iiwa14 among the book's two mesh obstacles (circle_two_obstacles.toml), each method in
turn (qp, baornn-improved) in viser's live page (articula/viewer/live.py) with one browser
tab connected when Debian's Chromium and Playwright are here (headless, software WebGL; else,
or with --no-browser, none, and `browser_connected` says so), paced at the scene's 10 ms
period like `articula live`:
  live_period_ms          median wall time [ms] of one period: gizmo poses read, planner step,
                          clearance recorded, and every DRAW_EVERY-th period (33 Hz) the arm's
                          link poses, colours and readout computed and handed to the painter
                          thread that pushes them to the page (the worse method's)
  live_overrun_fraction   fraction of periods longer than dt (the worse method's)
  <method>_period_ms, <method>_overrun_fraction, <method>_planner_ms (the step alone),
  <method>_paint_ms       median wall time [ms] of one picture's push on the painter thread
"""

from __future__ import annotations

import contextlib
import shutil
import socket
import statistics
import time
from pathlib import Path
from typing import Any

import viser
from common import run

from articula.book.study import packaged
from articula.viewer.live import Live, LiveScene

METHODS = ("qp", "baornn-improved")


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def _tab(url: str, wanted: bool):
    """A headless Chromium tab on url while the block runs; None without a browser (or not
    `wanted`)."""
    chromium = shutil.which("chromium") if wanted else None
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        chromium = None
    if chromium is None:
        yield None
        return
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=[
            "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader"])  # fmt: skip
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.goto(url)
        page.get_by_text("Connected").wait_for(timeout=60_000)
        yield page
        browser.close()


def measure(periods: int, no_browser: bool) -> dict[str, Any]:
    """Each method's paced live periods; the keys of the module's docstring."""
    scene_file = Path(packaged("ch1", "circle_two_obstacles.toml"))
    m: dict[str, Any] = {"periods": periods}
    for method in METHODS:
        port = _port()
        server = viser.ViserServer(host="127.0.0.1", port=port, verbose=False)
        try:
            live = Live(server, LiveScene.load(scene_file, method))
            try:
                walls, steps = _paced(live, f"http://127.0.0.1:{port}", periods, no_browser, m)
            finally:
                live.close()
        finally:
            server.stop()
        key = method.replace("-", "_")
        m[f"{key}_paint_ms"] = statistics.median(live.painter.paint_ms)
        m[f"{key}_period_ms"] = 1e3 * statistics.median(walls)
        m[f"{key}_planner_ms"] = 1e3 * statistics.median(steps)
        m[f"{key}_overrun_fraction"] = sum(w > live.dt for w in walls) / len(walls)
        m["dt_ms"] = 1e3 * live.dt
    m["live_period_ms"] = max(m[f"{k.replace('-', '_')}_period_ms"] for k in METHODS)
    m["live_overrun_fraction"] = max(m[f"{k.replace('-', '_')}_overrun_fraction"] for k in METHODS)
    return m


def _paced(
    live: Live, url: str, periods: int, no_browser: bool, m: dict[str, Any]
) -> tuple[list[float], list[float]]:
    """(wall times, planner times) [s] of `periods` live periods paced at dt, a tab on url
    unless `no_browser` (m["browser_connected"] says whether one was)."""
    with _tab(url, not no_browser) as page:
        m["browser_connected"] = page is not None
        for _ in range(20):  # warm-up: kernels, the page's first frames
            live.period()
        walls, steps = [], []
        next_period = time.perf_counter()
        for _ in range(periods):
            start = time.perf_counter()
            steps.append(live.period())
            walls.append(time.perf_counter() - start)
            next_period += live.dt
            pause = next_period - time.perf_counter()
            if pause > 0:
                time.sleep(pause)
            else:
                next_period = time.perf_counter()
    return walls, steps


def table(m: dict[str, Any]) -> tuple[str, list[str], list[list[str]]]:
    """One row per method."""
    rows = [[method, f"{m[f'{k}_period_ms']:.2f}", f"{m[f'{k}_planner_ms']:.2f}",
             f"{m[f'{k}_overrun_fraction']:.3f}"]
            for method in METHODS for k in [method.replace("-", "_")]]  # fmt: skip
    tab = "one Chromium tab connected" if m["browser_connected"] else "no browser connected"
    title = f"articula live, {m['periods']} periods of {m['dt_ms']:.0f} ms ({tab})"
    return title, ["method", "period ms", "planner ms", "overrun"], rows


if __name__ == "__main__":
    run(__doc__, measure, table, periods={"type": int, "default": 1000, "help": "periods"},
        no_browser={"action": "store_true", "help": "no tab connected (the browser's software"
                    " WebGL shares this machine's two cores)"})  # fmt: skip
