"""A drive of a UR10 against the fake UR controller: deadline misses, lateness, tracking.

    python benchmarks/drive.py [--json] [--duration S] [--rt-priority N]

`articula emulate ur` (the fake controller, the MuJoCo twin inside) and `articula drive --arm
ur:HOST` run as two processes on this machine, ur-rtde's real client between them: the UR10
of example-robot-data circles past a ball (the tests' scene, tests/arms.py) for --duration
seconds after its approach, the planner at 10 ms, servoJ at 500 Hz:
  deadline_miss_fraction  servo ticks released a whole tick (2 ms) or more late, of all
  latency_p99_ms          the ticks' lateness, 99th percentile [ms] (and _p50, _max)
  tracking_rms_mm         the measured tool from its reference once settled, RMS [mm]
  planner_step_p99_ms     the planner's wall time a 10 ms period, 99th percentile [ms]
  contacts                cycles in which the fake's twin saw a contact
Targets (issue 44, on an idle machine): deadline_miss_fraction 0, tracking_rms_mm ≤ 2,
contacts 0. The fake and the drive share the machine's cores: a busy machine misses more.
With --rt-priority N (needs root or CAP_SYS_NICE) a second lane runs the drive at SCHED_FIFO
priority N and the fake at N + 10, the two lanes in random order; its keys are prefixed rt_.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import pyarrow.parquet as pq
import tomli_w
from common import run

UR10_HOME = [0.0, -1.57, 1.57, -1.57, -1.57, 0.0]  # [rad]


def _scene(folder: Path, duration: float) -> Path:
    """The UR10 circling past a ball (as tests/arms.py's arm_scene("ur10"))."""
    share = Path(str(importlib.metadata.distribution("example-robot-data").locate_file(
        "cmeel.prefix/share")))  # fmt: skip
    urdf = share / "example-robot-data/robots/ur_description/urdf/ur10_robot.urdf"
    data = {
        "robot": {"urdf": str(urdf), "package_dirs": [str(share)], "q0": UR10_HOME},
        "planner": {"lambda_weight": 0.002, "d_min": 0.02, "duration": duration, "settle": 2.0},
        "trajectory": {"type": "circle", "axis_a": [0.0, 1.0, 0.0], "axis_b": [0.0, 0.0, 1.0],
                       "period": 10.0, "center": [0.7, 0.16, 0.55], "radius": 0.15},
        "obstacles": [{"name": "ball", "sphere": 0.06, "position": [0.66, 0.40, 0.66]}],
    }  # fmt: skip
    path = folder / "ur10.toml"
    path.write_text(tomli_w.dumps(data))
    return path


def measure(duration: float, rt_priority: int) -> dict[str, float]:
    lanes = [0, rt_priority] if rt_priority else [0]
    random.SystemRandom().shuffle(lanes)
    m: dict[str, float] = {}
    for priority in lanes:
        prefix = "rt_" if priority else ""
        m |= {prefix + key: value for key, value in _lane(duration, priority).items()}
    return m


def _lane(duration: float, priority: int) -> dict[str, float]:
    """One drive against a fake; both under SCHED_FIFO when priority > 0."""
    fake_rt = ["--rt-priority", str(priority + 10)] if priority else []
    drive_rt = ["--rt-priority", str(priority)] if priority else []
    rng = random.SystemRandom()
    host = f"127.{rng.randint(1, 254)}.{rng.randint(1, 254)}.{rng.randint(1, 254)}"
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scene, log = _scene(folder, duration), folder / "fake.parquet"
        articula = [sys.executable, "-m", "articula"]
        fake = subprocess.Popen(
            [*articula, "emulate", "ur", "--scene", str(scene), "--host", host, "--log", str(log),
             *fake_rt],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=os.environ,
        )  # fmt: skip
        try:
            fake.stdout.readline()  # "ur controller at ...": it listens
            subprocess.run(
                [*articula, "drive", str(scene), "--arm", f"ur:{host}", "--out",
                 str(folder / "run"), *drive_rt],
                check=True, stdout=subprocess.DEVNULL,
            )  # fmt: skip
        finally:
            fake.send_signal(signal.SIGTERM)
            fake.wait()
        m = json.loads((folder / "run/record.json").read_text())["metrics"]
        contacts = pq.read_table(log)["contacts"].to_numpy()
    return {
        "deadline_miss_fraction": m["servo_deadline_miss_fraction"],
        "latency_p50_ms": m["servo_latency_p50_ms"],
        "latency_p99_ms": m["servo_latency_p99_ms"],
        "latency_max_ms": m["servo_latency_max_ms"],
        "tracking_rms_mm": 1e3 * m["plant_rms_error"],
        "planner_step_p99_ms": m["planner_step_p99_ms"],
        "contacts": float((contacts > 0).sum()),
        "ticks": m["servo_releases"],
    }


def table(m: dict[str, float]) -> tuple[str, list[str], list[list[str]]]:
    return (
        "articula drive --arm ur against the fake controller",
        ["measure", "value"],
        [[name, f"{value:.4g}"] for name, value in m.items()],
    )


if __name__ == "__main__":
    run(__doc__, measure, table,
        duration={"type": float, "default": 8.0, "help": "the path's duration [s]"},
        rt_priority={"type": int, "default": 0,
                     "help": "a lane under SCHED_FIFO at this priority too (0: none)"})  # fmt: skip
