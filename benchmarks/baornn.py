"""Cost of one BAORNN iteration on the iiwa14 with two mesh obstacles (issue 4 target).

    python benchmarks/baornn.py [--json]

One iteration of Algorithm 1 evaluates the objective at three points (two antennae and the
candidate), each with the forward kinematics and the minimum link-obstacle distance. Timed at
configurations taken from a tracking run of configs/ch1/circle_two_obstacles.toml (Λ = 0.005,
d_min = 0.002 m), best of 5 repeats, median over the configurations:
  iteration_us        Baornn.iterate: one compiled iteration per call (scene/gjk.py,
                      scene/compiled_clearance.py, planning/baornn_kernel.py)
  step_iteration_us   Baornn.step per iteration: a control period of 10 iterations per call
  iteration_coal_us   the same Baornn.iterate on the Pinocchio + coal path (the baseline)
  bare_calls_us       three kinematics + distance evaluations as a bare Pinocchio/coal loop
                      from Python (benchmarks/distance.py's bare loop), nothing else
Target: iteration_us <= 40.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable
from importlib import resources
from pathlib import Path

import numpy as np
from distance import bare_coal_loop

from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.objective import Objective
from articula.planning.track import track
from articula.planning.trajectories import Circle
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

REPEATS = 5


def measure() -> dict[str, float]:
    path = Path(
        str(
            resources.files("articula.experiments")
            / "configs"
            / "ch1"
            / "circle_two_obstacles.toml"
        )
    )
    scene, q0 = build_scene(load_scene_spec(load_toml(path)), path.parent)
    objective = Objective(scene, 0.005, 1.0, 0.002)
    coal_objective = Objective(scene, 0.005, 1.0, 0.002)
    object.__setattr__(coal_objective, "compiled", None)  # force the Pinocchio + coal path
    planner = Baornn(objective, BaornnParams(0.3, 0.5, 10), np.random.default_rng(0))
    coal_planner = Baornn(coal_objective, BaornnParams(0.3, 0.5, 10), np.random.default_rng(0))
    circle = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)
    run = track(planner, circle, q0, 0.01, 10.0)
    bare_min = bare_coal_loop(scene)
    robot = scene.robot
    times: dict[str, list[float]] = {k: [] for k in ("iteration", "step", "coal", "bare")}
    for n in range(0, len(run.t), 5):
        q, x_ref, t = run.q[n], run.x_ref[n], run.t[n]
        g = objective.value(q, x_ref, t)
        times["iteration"].append(_best(planner.iterate, q, g, x_ref, t))
        times["step"].append(_best(planner.step, q, x_ref, t) / 10)
        times["coal"].append(_best(coal_planner.iterate, q, g, x_ref, t))
        times["bare"].append(_best(_bare_evaluations, bare_min, robot, q))
    m = {f"{k}_us": statistics.median(v) / 1e3 for k, v in times.items()}
    return {
        "iteration_us": m["iteration_us"],
        "step_iteration_us": m["step_us"],
        "iteration_coal_us": m["coal_us"],
        "bare_calls_us": m["bare_us"],
        "speedup_vs_coal": m["coal_us"] / m["iteration_us"],
        "configurations": float(len(times["iteration"])),
    }


def _best(call: Callable[..., object], *args: object) -> float:
    """Fastest of REPEATS calls [ns]: the least disturbed by other load on the machine."""
    best = np.inf
    for _ in range(REPEATS):
        start = time.perf_counter_ns()
        call(*args)
        best = min(best, time.perf_counter_ns() - start)
    return best


def _bare_evaluations(bare_min: Callable[[np.ndarray], float], robot: object, q: np.ndarray):
    """Three kinematics + minimum-distance evaluations, as one iteration needs."""
    for _ in range(3):
        bare_min(q)
        robot.forward(q)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    m = measure()
    if args.json:
        print(json.dumps(m))
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(
        title=f"one BAORNN iteration, median over {int(m['configurations'])} configurations"
    )
    for col in ("measure", "µs", "target"):
        table.add_column(col)
    table.add_row("iteration_us (Baornn.iterate, compiled)", f"{m['iteration_us']:.1f}", "<= 40")
    table.add_row("step_iteration_us (Baornn.step / 10)", f"{m['step_iteration_us']:.1f}", "")
    table.add_row("iteration_coal_us (Pinocchio + coal path)", f"{m['iteration_coal_us']:.1f}", "")
    table.add_row(
        "bare_calls_us (3 × FK + bare coal min distance)", f"{m['bare_calls_us']:.1f}", ""
    )
    table.add_row("speedup_vs_coal", f"{m['speedup_vs_coal']:.2f}×", "")
    Console().print(table)


if __name__ == "__main__":
    main()
