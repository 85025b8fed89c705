"""The first control period of a live loop: compiled before reset() returns (issue 26 target).

    python benchmarks/cold_start.py [--json] [--method NAME] [--steps N]

Each controller runs in fresh processes on book/ch1/configs/circle_two_obstacles.toml (its
scene and [planner] table, the method replaced), one 10 ms period per step() from the home
position, every call timed alone:
  import_ms            importing the online controller and the scene loader (a fresh
                       process, numba's cache warm)
  reset_ms             OnlineController.reset: the start's checks and the warm-up that
                       compiles, or loads from numba's cache, every kernel a step runs
  cold_reset_ms        the same with numba's cache empty (NUMBA_CACHE_DIR a new folder):
                       everything compiles
  cold_first_step_ms   the first step() after that cold reset
  warm_first_step_ms   the first step() after reset() with the cache warm
  median_step_ms       the median of the next `steps` step() calls (the baseline)
  max_step_ms          the slowest of those
  warm_over_median     warm_first_step_ms / median_step_ms (target ≤ 3)
The top-level keys are those of --method (default baornn-improved); `methods` holds every
method's, measured the same way.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

METHODS = ("baornn", "baornn-improved", "pinv", "dls", "qp")


def child(method: str, steps: int) -> None:
    """One fresh process: import, build, reset and step; prints its times as JSON."""
    started = time.perf_counter()
    from articula.book.study import packaged
    from articula.experiments.plan import build_plan
    from articula.loops.online import OnlineController
    from articula.validation import load_toml

    import_ms = 1e3 * (time.perf_counter() - started)
    path = packaged("ch1", "circle_two_obstacles.toml")
    plan = build_plan(load_toml(path), path.parent, str(path))
    dt = plan.spec.dt
    controller = OnlineController(plan.planner(method), dt)
    start = time.perf_counter()
    controller.reset(plan.q0)
    reset_ms = 1e3 * (time.perf_counter() - start)
    times = []
    for k in range(steps + 1):
        target = plan.reference(k * dt)
        start = time.perf_counter()
        controller.step(target)
        times.append(1e3 * (time.perf_counter() - start))
    print(json.dumps({"import_ms": import_ms, "reset_ms": reset_ms, "first_step_ms": times[0],
                      "median_step_ms": statistics.median(times[1:]),
                      "max_step_ms": max(times[1:])}))  # fmt: skip


def _spawn(method: str, steps: int, cache: str) -> dict[str, float]:
    """Run `child` in a new interpreter with numba's cache in `cache`."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    out = subprocess.run(
        [sys.executable, __file__, "--child", method, str(steps)],
        env=env, capture_output=True, text=True, check=True,
    )  # fmt: skip
    return json.loads(out.stdout.splitlines()[-1])


def measure_method(method: str, steps: int) -> dict[str, float]:
    """The measures of one method: a cold process, then a warm one on the same cache."""
    with tempfile.TemporaryDirectory(prefix="articula-numba-") as cache:
        cold = _spawn(method, 3, cache)
        warm = _spawn(method, steps, cache)
    return {
        "import_ms": warm["import_ms"],
        "reset_ms": warm["reset_ms"],
        "cold_reset_ms": cold["reset_ms"],
        "cold_first_step_ms": cold["first_step_ms"],
        "warm_first_step_ms": warm["first_step_ms"],
        "median_step_ms": warm["median_step_ms"],
        "max_step_ms": warm["max_step_ms"],
        "warm_over_median": warm["first_step_ms"] / warm["median_step_ms"],
    }


def measure(method: str, steps: int) -> dict:
    methods = {m: measure_method(m, steps) for m in METHODS}
    return {**methods[method], "method": method, "steps": steps, "methods": methods}


def table(m: dict) -> tuple[str, list[str], list[list[str]]]:
    keys = ["import_ms", "reset_ms", "cold_reset_ms", "cold_first_step_ms",
            "warm_first_step_ms", "median_step_ms", "max_step_ms", "warm_over_median"]  # fmt: skip
    rows = [[name, *(f"{values[k]:.3g}" for k in keys)] for name, values in m["methods"].items()]
    return f"First control period, {m['steps']} steps (ms)", ["method", *keys], rows


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        child(sys.argv[2], int(sys.argv[3]))
    else:
        from common import run

        run(__doc__, measure, table,
            method={"default": "baornn-improved", "choices": METHODS, "help": "top-level keys"},
            steps={"type": int, "default": 300, "help": "steps timed after the first"})  # fmt: skip
