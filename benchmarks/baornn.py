"""Cost of one BAORNN iteration on the iiwa14 with two mesh obstacles (issue 4 target).

    python benchmarks/baornn.py [--json]

One iteration of Algorithm 1 evaluates the objective at three points (two antennae and the
candidate), each with the forward kinematics and the minimum link-obstacle distance. Timed at
configurations taken from a tracking run of configs/ch1/circle_two_obstacles.toml (Λ = 0.005,
d_min = 0.002 m), median per iteration:
  iteration_us     Baornn.iterate (projection, objective, acceptance)
  bare_calls_us    the same three kinematics + distance evaluations as a bare Pinocchio/coal
                   loop from Python (benchmarks/distance.py's bare loop), nothing else
Target: iteration_us <= 40.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
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
        str(resources.files("articula.experiments") / "configs" / "ch1" / "two_obstacles.toml")
    )
    scene, q0 = build_scene(load_scene_spec(load_toml(path)), path.parent)
    objective = Objective(scene, 0.005, 1.0, 0.002)
    planner = Baornn(objective, BaornnParams(0.3, 0.5, 10), np.random.default_rng(0))
    circle = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)
    run = track(planner, circle, q0, 0.01, 10.0)
    samples = range(0, len(run.t), 5)
    clock = time.perf_counter_ns
    iteration, bare = [], []
    bare_min = bare_coal_loop(scene)
    robot = scene.robot
    for n in samples:
        q, x_ref, t = run.q[n], run.x_ref[n], run.t[n]
        g = objective.value(q, x_ref, t)
        best = np.inf
        for _ in range(REPEATS):
            start = clock()
            planner.iterate(q, g, x_ref, t)
            best = min(best, clock() - start)
        iteration.append(best)
        best = np.inf
        for _ in range(REPEATS):
            start = clock()
            for _ in range(3):
                bare_min(q)
                robot.forward(q)
            best = min(best, clock() - start)
        bare.append(best)
    return {
        "iteration_us": statistics.median(iteration) / 1e3,
        "bare_calls_us": statistics.median(bare) / 1e3,
        "configurations": float(len(iteration)),
    }


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
    table.add_row("iteration_us (Baornn.iterate)", f"{m['iteration_us']:.1f}", "<= 40")
    table.add_row(
        "bare_calls_us (3 × FK + bare coal min distance)", f"{m['bare_calls_us']:.1f}", ""
    )
    Console().print(table)


if __name__ == "__main__":
    main()
