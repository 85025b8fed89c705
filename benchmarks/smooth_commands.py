"""How smoothly each method commands the arm: acceleration use against tracking and clearance.

    python benchmarks/smooth_commands.py [--json] [--duration 25] [--methods baornn,qp]

On the book's two-obstacle circle (iiwa14), the Panda tight scene (tests/arms.py: a box, a ball
and a mesh, d_min 5 mm) and a UR10 past a ball (d_min 20 mm), each method plans with the
default settings (limits "velocity+acceleration"), BAORNN and baornn-improved with
`smoothing = "none"` (the search's commands) and "acceleration" (planning/smooth.py); once
settled:
  accel_rms_ratio     RMS commanded acceleration over its limit (second differences)
  saturated_fraction  share of periods with some joint at ≥ 0.9 of its acceleration limit
  rms_error           tracking error RMS [mm]
  min_clearance       smallest link-obstacle clearance over the run [mm] (and once settled)
Needs the dev extra (pybullet, example-robot-data); run from the repository's root.
"""

from __future__ import annotations

import sys
from pathlib import Path

from common import run

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/arms.py's scenes

from articula.book.study import packaged
from articula.experiments.plan import PlanConfig, load_plan, run_plan
from articula.validation import parse_model
from tests.arms import arm_scene

METHODS = "baornn,baornn-improved,qp"
COLUMNS = ("accel_rms_ratio", "saturated_fraction", "rms_error", "min_clearance",
           "min_clearance_settled")  # fmt: skip
SEARCHES = ("baornn", "baornn-improved")  # the methods `smoothing` applies to


def scenes(duration: float) -> dict[str, dict]:
    """The scenes by name, as plan configs of `duration` seconds."""
    book = load_plan(packaged("ch1", "circle_two_obstacles.toml"))
    book["planner"] = {**book["planner"], "duration": duration}
    return {"book circle": book, "panda tight": arm_scene("panda", duration),
            "ur10": arm_scene("ur10", duration)}  # fmt: skip


def measure(duration: float, methods: str) -> dict:
    rows = {}
    for scene, data in scenes(duration).items():
        for method in methods.split(","):
            for smoothing in ("none", "acceleration") if method in SEARCHES else ("",):
                planner = {**data["planner"], "method": method, "tolerance": 10.0}
                planner |= {"smoothing": smoothing} if smoothing else {}
                body = {k: v for k, v in {**data, "planner": planner}.items() if k != "experiment"}
                metrics = run_plan(parse_model(PlanConfig, body, scene)).metrics
                name = f"{scene} / {method}" + (f" ({smoothing})" if smoothing else "")
                rows[name] = {k: metrics[k] for k in COLUMNS}
    return rows


def table(m: dict) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        [name, f"{r['accel_rms_ratio']:.3f}", f"{100 * r['saturated_fraction']:.1f} %",
         f"{1e3 * r['rms_error']:.4f}", f"{1e3 * r['min_clearance']:.2f}",
         f"{1e3 * r['min_clearance_settled']:.2f}"]
        for name, r in m.items()
    ]  # fmt: skip
    columns = ["scene / method (smoothing)", "accel RMS / limit", "saturated", "RMS error mm",
               "min clear. mm", "settled min clear. mm"]  # fmt: skip
    return "acceleration use once settled (default limits)", columns, rows


if __name__ == "__main__":
    run(
        __doc__,
        measure,
        table,
        duration={"type": float, "default": 25.0, "help": "each run's path time [s]"},
        methods={"default": METHODS, "help": "comma-separated methods"},
    )
