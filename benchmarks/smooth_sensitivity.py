"""How much the smoothed searches' outcome depends on the smoothing's own constants.

    python benchmarks/smooth_sensitivity.py [--json] [--twin]

baornn-improved on the book's two-obstacle circle (iiwa14, 25 s of path; with --twin 10 s
closed on the MuJoCo twin at 1 kHz, as tests/sim/test_plant.py), once with the defaults and
once with each variation of a constant of planning/smooth.py or baornn_improved.TRADE_CAP
that should not change the outcome: the acceleration cost ±3 %, the damping 0.1 and 0.3, the
error cap 1 mm, 2 mm and none. A loop that falls into a trap (a joint at its limit, a link
pair at its floor, the path moving away) shows as an RMS error of millimetres in one row.
Run from the repository's root.
"""

from __future__ import annotations

import sys
from pathlib import Path

from common import run

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import articula.planning.baornn_improved as improved
import articula.planning.smooth as smooth
from articula.book.study import packaged
from articula.experiments.plan import PlanConfig, load_plan, run_plan
from articula.validation import parse_model

VARIATIONS = {
    "defaults": {},
    "acceleration cost −3 %": {"ACCELERATION_COST": 0.97 * smooth.ACCELERATION_COST},
    "acceleration cost +3 %": {"ACCELERATION_COST": 1.03 * smooth.ACCELERATION_COST},
    "damping 0.1": {"DAMPING": 0.1},
    "damping 0.3": {"DAMPING": 0.3},
    "error cap 1 mm": {"TRADE_CAP": 1e-3},
    "error cap 2 mm": {"TRADE_CAP": 2e-3},
    "no error cap": {"TRADE_CAP": float("inf")},
}


def _plan(twin: bool) -> dict:
    """The book circle's config for baornn-improved, open loop or closed on the twin."""
    data = load_plan(packaged("ch1", "circle_two_obstacles.toml"))
    data.pop("experiment", None)
    planner = {**data["planner"], "method": "baornn-improved", "tolerance": 10.0}
    if twin:
        planner |= {"duration": 10.0, "settle": 3.0}
        data |= {"servo": {"rate": 1000}, "plant": {"type": "mujoco"}}
    else:
        planner |= {"duration": 25.0}
    return {**data, "planner": planner}


def measure(twin: bool) -> dict:
    body, rows = _plan(twin), {}
    defaults = {**vars(smooth), "TRADE_CAP": improved.TRADE_CAP}
    for name, changes in VARIATIONS.items():
        for key, value in changes.items():
            setattr(improved if key == "TRADE_CAP" else smooth, key, value)
        try:
            metrics = run_plan(parse_model(PlanConfig, body, "book circle")).metrics
        finally:
            for key in changes:
                setattr(improved if key == "TRADE_CAP" else smooth, key, defaults[key])
        error = "plant_rms_error" if twin else "rms_error"
        rows[name] = {"rms_error": metrics[error], "min_clearance": metrics["min_clearance"],
                      "min_clearance_settled": metrics["min_clearance_settled"],
                      "saturated_fraction": metrics["saturated_fraction"]}  # fmt: skip
    return rows


def table(m: dict) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [[name, f"{1e3 * r['rms_error']:.3f}", f"{1e3 * r['min_clearance']:.1f}",
             f"{1e3 * r['min_clearance_settled']:.1f}", f"{100 * r['saturated_fraction']:.1f} %"]
            for name, r in m.items()]  # fmt: skip
    return ("baornn-improved on the book circle, one constant varied",
            ["variation", "RMS error mm", "min clearance mm", "settled min clearance mm",
             "saturated"], rows)  # fmt: skip


if __name__ == "__main__":
    run(
        __doc__,
        measure,
        table,
        twin={"action": "store_true", "help": "closed on the MuJoCo twin (10 s)"},
    )
