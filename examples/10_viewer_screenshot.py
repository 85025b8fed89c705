"""Plan a run, open it in `articula view` with headless Chromium, and save a screenshot.

The book's circle past two obstacles (Sect. 1.4.3) is planned with the NEO-style QP through
the library (`run_to_folder`, the call behind `articula plan`) into a run folder. The script
then serves that folder with `articula view RUN --port PORT` as a subprocess, opens the page
in Debian's Chromium under Playwright (software WebGL), waits until the 3-D scene is drawn,
moves the time slider to the middle of the run, saves a screenshot and stops the viewer with
Ctrl-C (SIGINT), its normal way out. It prints the run folder, the URL and the screenshot.
Needs `apt-get install -y chromium` and Playwright (the dev extra); Playwright's own browser
download is not used.

    .venv/bin/python examples/10_viewer_screenshot.py [--quick] [--out DIR]
"""

# needs: chromium

import argparse
import os
import shutil
import signal
import socket
import subprocess
import sys
from importlib import resources
from pathlib import Path

from PIL import Image
from playwright.sync_api import sync_playwright

from articula.experiments.plan import load_plan
from articula.runs.runner import run_to_folder

SCENE_FILE = Path(str(resources.files("articula") / "book/ch1/configs/circle_two_obstacles.toml"))
CHROMIUM_ARGS = ["--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                 "--enable-unsafe-swiftshader"]  # fmt: skip


def free_port():
    """A TCP port nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_viewer(run, port, log):
    """`articula view RUN --port PORT` as a subprocess; returns it once it prints its URL."""
    command = [sys.executable, "-m", "articula", "view", str(run), "--port", str(port)]
    viewer = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=log, text=True)
    for line in viewer.stdout:  # until its URL line, or its end (then stdout closes)
        if f"127.0.0.1:{port} (Ctrl-C stops it)" in line:
            return viewer
    raise SystemExit(f"the viewer exited with status {viewer.wait()}; see {log.name}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a 2 s run instead of 10 s")
    parser.add_argument("--out", type=Path, default=Path("example_output", Path(__file__).stem))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    config = load_plan(SCENE_FILE)  # the scene file as a baornn.plan config, paths absolute
    duration = 2.0 if args.quick else 10.0  # [s]
    config["planner"] |= {"method": "qp", "duration": duration, "settle": duration / 2}
    run = args.out / "run"
    record = run_to_folder(config, run, str(SCENE_FILE), force=True)
    metrics = record["metrics"]

    port = free_port()
    url = f"http://127.0.0.1:{port}"
    screenshot = args.out / "viewer.png"
    with open(args.out / "viewer.log", "w") as log:
        viewer = start_viewer(run, port, log)
        try:
            with sync_playwright() as playwright:
                browser = playwright.chromium.launch(
                    executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS
                )
                page = browser.new_page(viewport={"width": 1280, "height": 800})
                page.goto(url)
                page.get_by_text("Connected").wait_for(timeout=60_000)
                page.get_by_text("closest:").first.wait_for(timeout=60_000)  # the scene is in
                page.add_style_tag(content="#webgl-software-rendering {display: none}")  # notice
                time_box = page.locator("input[inputmode='decimal']:visible").first  # the slider
                time_box.fill(f"{duration / 2:.2f}")
                time_box.press("Enter")
                page.get_by_text(f"t = {duration / 2:.2f} s").wait_for(timeout=30_000)
                page.wait_for_timeout(3000)  # software WebGL draws a few frames
                page.screenshot(path=screenshot)
                browser.close()
        finally:
            viewer.send_signal(signal.SIGINT)  # Ctrl-C: the viewer's normal way out
            status = viewer.wait(timeout=15)

    print(f"{'run folder':<14}{os.path.relpath(run)}")
    print(f"{'run':<14}qp, {duration:g} s: RMS error {1e3 * metrics['rms_error']:.4f} mm, "
          f"min clearance {1e3 * metrics['min_clearance']:.1f} mm")  # fmt: skip
    print(f"{'viewer':<14}{url} (stopped by SIGINT, exit status {status})")
    width, height = Image.open(screenshot).size
    print(f"{'screenshot':<14}{os.path.relpath(screenshot)} ({width} × {height} px, "
          f"{screenshot.stat().st_size / 1024:.0f} KiB)")  # fmt: skip


if __name__ == "__main__":
    main()
