"""The fake UR controller as the tests run it: `articula emulate ur` in a process of its own
(ur-rtde's client holds the GIL while it connects, so the fake cannot share the test's
process), each on a loopback address of its own, its lines read as they come.

Where the machine allows real-time scheduling (root or CAP_SYS_NICE), the fake plays its
cycle and the drives stream under SCHED_FIFO (`--rt-priority`, arms.realtime), as a
controller and a servo host do: other work on a loaded machine then cannot starve the stream
past the controller's 100 ms watchdog. Elsewhere they run as ordinary processes."""

from __future__ import annotations

import os
import random
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import ClassVar

import numpy as np
import pyarrow.parquet as pq
import tomli_w

from tests.arms import arm_scene
from tests.realtime import DRIVE_PRIORITY, realtime_allowed, realtime_here

__all__ = [
    "DRIVE_PRIORITY",
    "Fake",
    "Process",
    "realtime_allowed",
    "realtime_here",
    "rt_options",
    "scene_file",
]

HANG = 120.0  # [s] a wait this long means the fake hangs (a guard, not a measurement)
ROOT = Path(__file__).resolve().parents[2]
FAKE_PRIORITY = 20  # SCHED_FIFO: the controller's cycle above the stream (DRIVE_PRIORITY)


def rt_options(priority: int) -> list[str]:
    """`--rt-priority priority` where the machine allows it, else nothing."""
    return ["--rt-priority", str(priority)] if realtime_allowed() else []


def environment() -> dict[str, str]:
    """The environment of a subprocess: this checkout's sources first."""
    paths = [str(ROOT / "src"), str(ROOT), os.environ.get("PYTHONPATH", "")]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in paths if p)}


def scene_file(
    folder: Path, duration: float = 4.0, robot: dict | None = None, name: str = "ur10"
) -> Path:
    """A UR scene (tests.arms: "ur10", "ur5" or "ur5e") of `duration` [s] written to
    folder/NAME.toml, its [robot] updated with `robot`."""
    data = arm_scene(name, duration)
    if robot is not None:
        data["robot"] |= robot
    path = folder / f"{name}.toml"
    path.write_text(tomli_w.dumps(data))
    return path


class Process:
    """A CLI process whose stdout and stderr lines are collected as they come; each one a
    test leaves running is killed after it (conftest).

    Args:
        args: the articula command's arguments.
    """

    running: ClassVar[list[Process]] = []

    def __init__(self, *args: str) -> None:
        Process.running.append(self)
        self.lines: list[str] = []
        self._changed = threading.Condition()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "articula", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=environment(),
        )
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.process.stdout:
            with self._changed:
                self.lines.append(line.rstrip("\n"))
                self._changed.notify_all()
        with self._changed:
            self._changed.notify_all()

    def wait_for(self, pattern: str) -> str:
        """The first line matching `pattern` (waits for it; fails if the process ends)."""
        found = re.compile(pattern)

        def match() -> str | None:
            return next((line for line in self.lines if found.search(line)), None)

        with self._changed:
            ok = self._changed.wait_for(
                lambda: match() is not None or self.process.poll() is not None, HANG
            )
        assert ok and match() is not None, f"no line {pattern!r} in {self.lines}"
        return match()

    def end(self, sig: int = signal.SIGTERM) -> int:
        """Send `sig` (if still running) and wait for the exit status."""
        if self.process.poll() is None:
            self.process.send_signal(sig)
        return self.process.wait(HANG)

    @classmethod
    def kill_all(cls) -> None:
        """Kill every process a test left running (a failed test's)."""
        for process in cls.running:
            if process.process.poll() is None:
                process.process.kill()
                process.process.wait()
        cls.running.clear()


class Fake(Process):
    """`articula emulate ur` on a loopback address of its own, its log written at the end.

    Args:
        scene: the scene file.
        folder: where its log goes.
        start: the arm's joints at power-on [rad]; None: the scene's q0.
    """

    def __init__(self, scene: Path, folder: Path, start: list[float] | None = None) -> None:
        rng = random.SystemRandom()
        self.host = f"127.{rng.randint(1, 254)}.{rng.randint(1, 254)}.{rng.randint(1, 254)}"
        self.log_path = folder / f"fake-{self.host}.parquet"
        args = ["emulate", "ur", "--scene", str(scene), "--host", self.host]
        args += ["--log", str(self.log_path), *rt_options(FAKE_PRIORITY)]
        if start is not None:
            args += ["--start", ",".join(repr(v) for v in start)]
        super().__init__(*args)
        self.wait_for("ur controller at")

    def log(self) -> dict[str, np.ndarray]:
        """End the fake (SIGTERM) and read its log of every cycle."""
        self.end()
        table = pq.read_table(self.log_path)
        return {name: table[name].to_numpy() for name in table.column_names}


def until(predicate: Callable[[], bool]) -> None:
    """Wait for a state that another process sets (polled; fails after HANG)."""
    deadline = time.monotonic() + HANG
    while not predicate():
        assert time.monotonic() < deadline, "the state never came"
        time.sleep(0.001)


def joints(log: dict[str, np.ndarray], prefix: str) -> np.ndarray:
    """The log's six joint columns (q: measured, qc: commanded), shape (cycles, 6) [rad]."""
    return np.column_stack([log[f"{prefix}_{j}"] for j in range(1, 7)])
