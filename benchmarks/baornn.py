"""Cost of one BAORNN iteration on the iiwa14 with two mesh obstacles (issue 4 target).

    python benchmarks/baornn.py [--json]

One iteration of Algorithm 1 evaluates the objective at three points (two antennae and the
candidate), each with the forward kinematics and the minimum link-obstacle distance. Timed at
200 configurations of a tracking run of book/ch1/configs/circle_two_obstacles.toml (Λ = 0.005,
d_min = 0.002 m), one call per configuration in the run's order (so the GJK warm starts are
those a real run has, never a repeat of the same query), median over the configurations:
  iteration_us        Baornn.step / 10: an iteration as the planner runs it, ten per control
                      period in one compiled call (scene/gjk.py, scene/compiled_clearance.py,
                      planning/baornn_kernel.py), including the period's first evaluation
  single_iterate_us   one Baornn.iterate call (one iteration, one call from Python)
  iteration_coal_us   Baornn.step / 10 on the Pinocchio + coal path (the baseline)
  bare_calls_us       three minimum-distance evaluations (each with its forward kinematics)
                      as a bare Pinocchio/coal loop from Python (benchmarks/distance.py)
Target: iteration_us <= 40.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

import numpy as np
from common import run
from distance import bare_coal_loop

from articula.book.study import packaged
from articula.loops.tracking import track
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.objective import Objective
from articula.planning.trajectories import Circle
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml


def measure() -> dict[str, float]:
    path = packaged("ch1", "circle_two_obstacles.toml")
    scene, q0 = build_scene(load_scene_spec(load_toml(path)), path.parent)
    objective = Objective(scene, 0.005, 1.0, 0.002)
    coal_objective = Objective(scene, 0.005, 1.0, 0.002, use_compiled=False)
    planner = Baornn(
        objective, BaornnParams(c1=0.3, c2=0.5, iterations_per_step=10), np.random.default_rng(0)
    )
    coal_planner = Baornn(
        coal_objective,
        BaornnParams(c1=0.3, c2=0.5, iterations_per_step=10),
        np.random.default_rng(0),
    )
    circle = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)
    run = track(planner, circle, q0, 0.01, 10.0)
    bare_min = bare_coal_loop(scene)
    times: dict[str, list[float]] = {k: [] for k in ("step", "single", "coal", "bare")}
    for n in range(0, len(run.t), 5):
        q, x_ref, t = run.q[n], run.x_ref[n], run.t[n]
        g = objective.value(q, x_ref, t)
        times["step"].append(_once(planner.step, q, x_ref, t) / 10)
        times["single"].append(_once(planner.iterate, q, g, x_ref, t))
        times["coal"].append(_once(coal_planner.step, q, x_ref, t) / 10)
        times["bare"].append(_once(_bare_evaluations, bare_min, q))
    m = {k: statistics.median(v) / 1e3 for k, v in times.items()}
    return {
        "iteration_us": m["step"],
        "single_iterate_us": m["single"],
        "iteration_coal_us": m["coal"],
        "bare_calls_us": m["bare"],
        "speedup_vs_coal": m["coal"] / m["step"],
        "configurations": float(len(times["step"])),
    }


def _once(call: Callable[..., object], *args: object) -> float:
    """Wall time of one call [ns]."""
    start = time.perf_counter_ns()
    call(*args)
    return time.perf_counter_ns() - start


def _bare_evaluations(bare_min: Callable[[np.ndarray], float], q: np.ndarray) -> None:
    """Three minimum-distance evaluations (each runs the forward kinematics), as one
    iteration needs."""
    for _ in range(3):
        bare_min(q)


def table(m: dict[str, float]) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        ["iteration_us (Baornn.step / 10, compiled)", f"{m['iteration_us']:.1f}", "<= 40"],
        ["single_iterate_us (one Baornn.iterate call)", f"{m['single_iterate_us']:.1f}", ""],
        ["iteration_coal_us (Baornn.step / 10, coal)", f"{m['iteration_coal_us']:.1f}", ""],
        ["bare_calls_us (3 × FK + bare coal min distance)", f"{m['bare_calls_us']:.1f}", ""],
        ["speedup_vs_coal", f"{m['speedup_vs_coal']:.2f}×", ""],
    ]
    title = f"one BAORNN iteration, median over {int(m['configurations'])} configurations"
    return title, ["measure", "µs", "target"], rows


if __name__ == "__main__":
    run(__doc__, measure, table)
