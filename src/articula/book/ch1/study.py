"""Chapter 1's study: the book's runs and every method on every scene, through the runner."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import tomli_w

from articula.book.ch1.book_values import BOOK_RUNS, SCENES, SNAPSHOT_TIMES, SNAPSHOTS, Run
from articula.book.ch1.experiment import load_plan
from articula.book.study import Study, packaged, read_metrics, read_trace
from articula.runs.records import atomic_write
from articula.scene.config import build_scene, load_scene_spec
from articula.scene.scene import Scene
from articula.validation import load_toml

# Faithful iterations per period that cost as many objective evaluations as baornn-improved's
# 10 × (2·3 antenna pairs + 1 step) + 1 warm start = 71: 24 × 3 = 72.
EQUAL_ITERATIONS = 24
# Comparison rows: name -> [planner] overrides (each scene's file gives Λ, d_min and the rest).
METHODS = {
    "baornn": {"method": "baornn"},
    "baornn-improved": {"method": "baornn-improved"},
    "baornn-equal-evaluations": {"method": "baornn", "iterations_per_step": EQUAL_ITERATIONS},
    "pinv": {"method": "pinv"},
    "dls": {"method": "dls"},
    "qp": {"method": "qp"},
}
STOCHASTIC = ("baornn", "baornn-improved", "baornn-equal-evaluations")
FULL_SEEDS = (0, 1, 2, 3, 4)
SWEEP = "plan_sweep.toml"  # the study as a sweep file, written beside the report
RUNS = "runs"  # its sweep folder


@dataclass(frozen=True)
class Ch1Results:
    """Metrics of every run by name, and the scenes they ran in."""

    metrics: dict[str, dict[str, float]]
    scenes: dict[str, Scene]


def scene_path(scene: str) -> Path:
    """The packaged scene file of one of the book's scenes."""
    return packaged("ch1", SCENES[scene])


def comparison_runs(full: bool) -> list[Run]:
    """Every method on every scene (more seeds for the stochastic methods in full mode)."""
    runs = []
    for scene in SCENES:
        for method, overrides in METHODS.items():
            seeds = FULL_SEEDS if full and method in STOCHASTIC else (0,)
            for seed in seeds:
                if method == "baornn" and seed == 0:
                    continue  # the book run of the scene
                tag = method if seed == 0 else f"{method}_seed{seed}"
                runs.append(Run(f"{slug(scene)}_{tag}", scene, {**overrides, "seed": seed}))
    return runs


def plan_config(run: Run) -> dict[str, Any]:
    """The `baornn.plan` config of a run: its scene file with the run's overrides.

    A seed override goes to the top of the config; the tolerance is lifted so that every
    result is reported, however large its error, instead of refused.
    """
    data = load_plan(scene_path(run.scene))
    overrides = dict(run.overrides)
    if "seed" in overrides:
        data["seed"] = overrides.pop("seed")
    data["planner"] = {**data["planner"], **overrides, "tolerance": 1e3}
    return data


def run_study(study: Study) -> Ch1Results:
    """Plan every run into OUT/runs (resuming finished ones), draw the figures."""
    runs = [*BOOK_RUNS, *comparison_runs(study.full)]
    configs = {run.name: plan_config(run) for run in runs}
    study.out.mkdir(parents=True, exist_ok=True)
    spec = {"runs": list(configs.values())}
    atomic_write(study.out / SWEEP, tomli_w.dumps(spec).encode())
    study.sweep(list(configs.values()), RUNS)
    metrics = {name: read_metrics(study.out / RUNS, c) for name, c in configs.items()}
    scenes = {name: load_scene(name) for name in SCENES}
    _figures(study.out, configs, scenes)
    return Ch1Results(metrics, scenes)


def load_scene(name: str) -> Scene:
    """The Scene of one of the book's scenes."""
    path = scene_path(name)
    scene, _ = build_scene(load_scene_spec(load_toml(path), str(path)), path.parent)
    return scene


def _figures(out: Path, configs: Mapping[str, dict[str, Any]], scenes: Mapping[str, Scene]) -> None:
    """Paths, time series and snapshots of every book run."""
    from articula.book.ch1.figures import paths, snapshots, time_series

    for run in BOOK_RUNS:
        trace = read_trace(out / RUNS, configs[run.name])
        scene = scenes[run.scene]
        paths(scene, trace, run.title, out / f"{run.name}_paths.png")
        time_series(trace, run.title, out / f"{run.name}_series.png")
        if run.name in SNAPSHOTS:
            title = f"{SNAPSHOTS[run.name]}: snapshots, {run.title.split(': ')[1]}"
            snapshots(scene, trace, list(SNAPSHOT_TIMES), title, out / f"{run.name}_snapshots.png")


def slug(scene: str) -> str:
    """A scene name as part of a run name."""
    return scene.replace(" ", "_")
