"""`articula bench suite`: every articula method and mink on the same generated problems.

Each problem (bench/problems.py) is written as a scene file, problems/NNN/scene.toml with its
mesh obstacles beside it (`articula plan` runs it as it is), and tracked by every method from
its start for one lap of its path. A run succeeds when it has no colliding step (articula's
GJK clearance of every obstacle > 0), keeps every joint within its position limits and
every joint speed within its URDF limit (|Δq|/dt, 1e-6 relative slack for rounding), and
tracks with an RMS error below SUCCESS_RMS after SETTLE. A failed run is put in the first
class of FAILURES it falls in.

mink runs twice: with its default collision gain ("mink") and with the gain that makes its
collision bound a damper of the qp's rate ("mink-matched", bench/mink_peer.py); the summary
compares every method with the better of the two. Step times are per control period, taken
alone (perf_counter_ns around the call), the first period of a run (which may compile or
load a kernel) left out.
"""

from __future__ import annotations

import hashlib
import json
import statistics
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import tomli_w

from articula.bench.problems import D_MIN, DT, INFLUENCE, SETTLE, generate
from articula.errors import ArticulaError, ConfigError
from articula.experiments.plan import PlanSetup, build_plan
from articula.loops.stall import standing_still
from articula.planning.config import METHODS
from articula.runs import records
from articula.runs.backends import check_backend, execute_all
from articula.runs.folders import RESULTS, SUMMARY, claimed

ARTICULA_METHODS = METHODS
PEER_METHODS = ("mink", "mink-matched")
FAILURES = ("error", "collision", "joint_limits", "speed_limits", "tracking")
SUCCESS_RMS = 0.001  # [m] after SETTLE
STALLED_RUN = 0.1  # [s] a run that stood still this long off its path (settled) stalled
PROBLEMS = "problems"
PEERS_INSTALL = "pip install -e '.[peers]'"


def peers_missing() -> str | None:
    """Why mink cannot run here (None when it can).

    Returns:
        The missing module and how to install it, or None.
    """
    try:
        import mink  # noqa: F401
        import mujoco  # noqa: F401
    except ImportError as exc:
        return f"{exc.name} is not installed ({PEERS_INSTALL})"
    return None


def choose_methods(methods: str | None, missing: str | None) -> list[str]:
    """The methods of --methods: comma-separated names, or None for every articula method and,
    when mink can run, both peers.

    Args:
        methods: the option's value, or None.
        missing: why mink cannot run (peers_missing), or None.

    Returns:
        The chosen methods, in the order given.

    Raises:
        ConfigError: naming --methods, for an unknown or empty list or a peer that cannot run.
    """
    if methods is None:
        return list(ARTICULA_METHODS) + ([] if missing else list(PEER_METHODS))
    chosen = [m.strip() for m in methods.split(",") if m.strip()]
    unknown = [m for m in chosen if m not in ARTICULA_METHODS + PEER_METHODS]
    if unknown or not chosen:
        known = ", ".join(ARTICULA_METHODS + PEER_METHODS)
        raise ConfigError("--methods", f"unknown {unknown or 'none given'}; choose from {known}")
    if missing and any(m in PEER_METHODS for m in chosen):
        raise ConfigError("--methods", f"mink cannot run: {missing}")
    return chosen


def run_suite(
    robot: dict[str, Any],
    problems: int,
    seed: int,
    out: Path,
    methods: Sequence[str],
    workers: int = 1,
    dask: str | None = None,
    force: bool = False,
    progress: Callable[[int, int], None] | None = None,
    problem_class: str = "standard",
) -> dict[str, Any]:
    """Generate and run `problems` problems into `out`; returns the summary (also written to
    summary.json, beside results.parquet: one row per problem and method).

    Args:
        robot: a [robot] table (absolute paths) of the arm.
        problems: how many problems.
        seed: the suite's seed; problem i draws from default_rng([seed, i]).
        out: the suite folder; problems it finished before (same robot, seed and methods)
            are not run again.
        methods: articula methods and peers (PEER_METHODS) to run on every problem.
        workers: most worker processes (as for sweeps).
        dask: None, "local" or "tcp://HOST:PORT" of a Dask scheduler (as for sweeps).
        force: write into an `out` holding files articula did not write.
        progress: called with (problems done, problems), or None.
        problem_class: the problems' class (bench.problems.CLASSES): "standard" or "tight".

    Returns:
        The summary (summarize), as written to summary.json.
    """
    check_backend(dask)
    key = _suite_key(robot, seed, methods, problem_class)
    tasks = [
        {
            "robot": robot,
            "seed": seed,
            "index": i,
            "class": problem_class,
            "methods": list(methods),
            "key": key,
            "folder": str(out / PROBLEMS / f"{i:03d}"),
        }
        for i in range(problems)
    ]
    with claimed(out, "suite", force):
        done = {t["index"]: rows for t in tasks if (rows := _finished(t)) is not None}
        todo = [t for t in tasks if t["index"] not in done]
        if progress:
            progress(len(done), problems)
        for index, rows in execute_all(solve_problem, todo, workers, dask):
            done[index] = rows
            if progress:
                progress(len(done), problems)
        rows = [row for i in sorted(done) for row in done[i]]
        table = pa.Table.from_pylist([{k: v for k, v in r.items() if k != "step_us"} for r in rows])
        records.write_table(out / RESULTS, table)
        summary = summarize(rows, methods, robot, seed, problems) | {"class": problem_class}
        records.atomic_write(out / SUMMARY, (json.dumps(summary, indent=2) + "\n").encode())
    return summary


def _suite_key(robot: dict[str, Any], seed: int, methods: Sequence[str], problem_class: str) -> str:
    """What a finished problem's results depend on, hashed."""
    suite = {"robot": robot, "seed": seed, "methods": list(methods), "class": problem_class}
    text = json.dumps(suite, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _finished(task: Mapping[str, Any]) -> list[dict[str, Any]] | None:
    """The rows of a problem finished before with the same suite key, else None."""
    try:
        saved = json.loads((Path(task["folder"]) / "results.json").read_text())
    except (OSError, ValueError):
        return None
    return saved["rows"] if saved.get("key") == task["key"] else None


def solve_problem(task: Mapping[str, Any]) -> tuple[int, list[dict[str, Any]]]:
    """Generate problem task["index"], write its folder, run every method; (index, rows).

    Args:
        task: the problem's robot table, seed, index, class, methods, key (the suite's hash)
            and folder.

    Returns:
        The index and one row per method: problem, method, path, obstacles, success,
        failure, message, metrics (none after an error) and step_us (step times [µs]).
    """
    folder = Path(task["folder"])
    problem = generate(task["robot"], task["seed"], task["index"], task.get("class", "standard"))
    records.make_folder(folder)
    for name, mesh in problem.meshes.items():
        records.atomic_write(folder / name, mesh.export(file_type="stl"))
    records.atomic_write(folder / "scene.toml", tomli_w.dumps(problem.config).encode())
    config = problem.config
    plan = build_plan(config, folder, str(folder / "scene.toml"))
    steps = round(config["planner"]["duration"] / DT)
    targets_per_step = [plan.targets(n * DT) for n in range(steps)]
    rows = []
    for method in task["methods"]:
        row = {
            "problem": task["index"],
            "method": method,
            "path": problem.path_kind,
            "obstacles": len(config["obstacles"]),
        }
        rows.append(row | _run(method, plan, targets_per_step))
    saved = {"key": task["key"], "rows": rows}
    records.atomic_write(folder / "results.json", json.dumps(saved).encode())
    return task["index"], rows


def _run(method: str, plan: PlanSetup, targets: list) -> dict[str, Any]:
    """One method on one problem: its success, failure class, metrics and step times."""
    scene, q0 = plan.scene, plan.q0
    robot = scene.robot
    try:
        step = _controller(method, plan)
        qs = np.empty((len(targets), robot.nq))
        times = np.empty(len(targets), dtype=np.int64)
        for n, target in enumerate(targets):
            start = time.perf_counter_ns()
            qs[n] = step(target)
            times[n] = time.perf_counter_ns() - start
    except ArticulaError as exc:
        return {"success": False, "failure": "error", "message": str(exc), "step_us": []}
    position = np.array([t.position for t in targets])
    error = np.linalg.norm(np.array([robot.ee_position(q) for q in qs]) - position, axis=1)
    settled = np.arange(len(targets)) * DT >= SETTLE
    clearance = np.array([scene.min_distance(q) for q in qs])
    outside = (qs < robot.lower - 1e-9) | (qs > robot.upper + 1e-9)
    speed = np.abs(np.diff(np.vstack([q0, qs]), axis=0)) / DT
    limit = np.where(robot.velocity_limit > 0, robot.velocity_limit, np.inf)
    metrics = {
        "rms_error": float(np.sqrt(np.mean(error[settled] ** 2))),
        "max_error": float(error[settled].max()),
        "min_clearance": float(clearance.min()),
        "colliding_steps": int(np.sum(clearance <= 0.0)),
        "joint_limit_steps": int(np.sum(np.any(outside, axis=1))),
        "max_speed_ratio": float(np.max(speed / limit)),
        "median_step_us": float(np.median(times[1:]) / 1e3),
        "p99_step_us": float(np.percentile(times[1:], 99) / 1e3),
    }
    still = standing_still(robot, qs, q0, DT) & (error > SUCCESS_RMS)
    metrics["stalled_s"] = float(np.sum(still[settled])) * DT
    failed = {
        "collision": metrics["colliding_steps"] > 0,
        "joint_limits": metrics["joint_limit_steps"] > 0,
        "speed_limits": metrics["max_speed_ratio"] > 1.0 + 1e-6,
        "tracking": not metrics["rms_error"] < SUCCESS_RMS,
    }
    failure = next((name for name in FAILURES[1:] if failed[name]), None)
    step_us = [round(t / 1e3, 3) for t in times[1:]]
    return {
        "success": failure is None,
        "failure": failure,
        "message": None,
        **metrics,
        "step_us": step_us,
    }


def _controller(method: str, plan: PlanSetup) -> Callable[[Any], np.ndarray]:
    """A step function (target -> q [rad]) of `method` reset to the plan's q0."""
    if method in PEER_METHODS:
        from articula.bench.mink_peer import MinkArm, matched_gain  # the peers extra

        gain = matched_gain(DT, D_MIN, INFLUENCE) if method == "mink-matched" else 0.85
        arm = MinkArm(plan.scene, D_MIN, INFLUENCE, DT, gain=gain)
        arm.reset(plan.q0)
        return lambda target: arm.step(target.position)
    return plan.controller(method).step


def summarize(
    rows: Sequence[Mapping[str, Any]],
    methods: Sequence[str],
    robot: Mapping[str, Any],
    seed: int,
    problems: int,
) -> dict[str, Any]:
    """Per method: success rate, failures by class, stalls (runs that stood still off the
    path, error above SUCCESS_RMS, for STALLED_RUN or longer once settled), mean, median and
    p99 step time over all its periods, median RMS error and the smallest clearance; and each
    articula method's success rate less the better mink's and its mean step time over mink's
    (default gain).

    Args:
        rows: the rows of every problem and method (solve_problem), with their step_us.
        methods: the methods to summarize.
        robot: the suite's [robot] table, recorded.
        seed: the suite's seed, recorded.
        problems: the number of problems, recorded.

    Returns:
        The JSON-ready summary: robot, seed, problems, success_rms_m [m], settle_s [s], the
        statistics of each method under "methods" (step times [µs]) and, when a peer ran,
        best_mink_success_rate, and per articula method vs_best_mink and step_time_vs_mink.
    """
    out: dict[str, Any] = {
        "robot": dict(robot),
        "seed": seed,
        "problems": problems,
        "success_rms_m": SUCCESS_RMS,
        "settle_s": SETTLE,
        "methods": {},
    }
    for method in methods:
        mine = [r for r in rows if r["method"] == method]
        times = [t for r in mine for t in r["step_us"]]
        ran = [r for r in mine if r["failure"] != "error"]
        out["methods"][method] = {
            "success_rate": sum(r["success"] for r in mine) / max(len(mine), 1),
            "successes": sum(r["success"] for r in mine),
            "stalls": sum((r.get("stalled_s") or 0.0) >= STALLED_RUN for r in mine),
            "failures": {f: sum(r["failure"] == f for r in mine) for f in FAILURES},
            "mean_step_us": statistics.fmean(times) if times else None,
            "median_step_us": statistics.median(times) if times else None,
            "p99_step_us": float(np.percentile(times, 99)) if times else None,
            "median_rms_error_m": statistics.median(r["rms_error"] for r in ran) if ran else None,
            "min_clearance_m": min((r["min_clearance"] for r in ran), default=None),
        }
    peers = [out["methods"][m]["success_rate"] for m in PEER_METHODS if m in out["methods"]]
    if peers:
        best = max(peers)
        out["best_mink_success_rate"] = best
        peer = out["methods"].get("mink") or out["methods"][PEER_METHODS[1]]
        for method in ARTICULA_METHODS:
            if method in out["methods"]:
                mine = out["methods"][method]
                mine["vs_best_mink"] = mine["success_rate"] - best
                if mine["mean_step_us"] is not None and peer["mean_step_us"]:
                    mine["step_time_vs_mink"] = mine["mean_step_us"] / peer["mean_step_us"]
    return out
