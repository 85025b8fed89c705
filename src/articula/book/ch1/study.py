"""Chapter 1's study: the book's runs and every method on every scene, through the runner."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import tomli_w

from articula.book.ch1.book_values import (
    BOOK_RUNS,
    FULL_SEEDS,
    METHODS,
    SCENES,
    SNAPSHOT_TIMES,
    SNAPSHOTS,
    STOCHASTIC,
    Run,
    slug,
)
from articula.book.study import Study, packaged, read_metrics, read_trace
from articula.experiments.plan import NAME
from articula.planning.config import PlannerSpec
from articula.runs.records import atomic_write
from articula.scene.config import PACKAGE_URI, build_scene, load_scene_spec
from articula.scene.scene import Scene
from articula.validation import load_toml, parse_model

SWEEP = "plan_sweep.toml"  # the study as a sweep file, written beside the report
RUNS = "runs"  # its sweep folder


@dataclass(frozen=True)
class Ch1Results:
    """What the chapter's report shows.

    Attributes:
        metrics: every run's metrics, by run name.
        scenes: the Scene of each of the book's scenes.
        obstacles: each scene's obstacles as (name, mesh file, position [m]).
        settings: the complete [planner] table of the runs (a qp run of the rectangle scene:
            every method's parameters with their defaults filled in).
    """

    metrics: dict[str, dict[str, float]]
    scenes: dict[str, Scene]
    obstacles: dict[str, list[tuple[str, str, list[float]]]]
    settings: dict[str, Any]


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

    Its meshes are named inside the package (package://articula/...), so that the config, its
    hash and its run folder are the same on every machine and install; a seed override goes
    to the top of the config; the tolerance is lifted so that every result is reported,
    however large its error, instead of refused; BAORNN runs without joint speed or
    acceleration limits and the path starts at once wherever the tool is, as the book's does
    (the baselines' solvers keep the speed limits).
    """
    data = {"experiment": NAME, **load_toml(scene_path(run.scene))}
    for obstacle in data.get("obstacles", []):
        if "mesh" in obstacle:
            obstacle["mesh"] = f"{PACKAGE_URI}book/ch1/configs/{obstacle['mesh']}"
    overrides = dict(run.overrides)
    if "seed" in overrides:
        data["seed"] = overrides.pop("seed")
    # The book's Algorithm 1 has no joint limits on speed or acceleration and starts the path at
    # once: its runs keep none (limits = "none") and have no approach.
    data["planner"] = {
        **data["planner"],
        **overrides,
        "tolerance": 1e3,
        "limits": "none",
        "approach": "none",
    }
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
    obstacles = {
        name: [
            (o["name"], o["mesh"], o["position"]) for o in load_toml(scene_path(name))["obstacles"]
        ]
        for name in SCENES
    }
    table = {**load_toml(scene_path("rectangle"))["planner"], "method": "qp"}
    settings = parse_model(PlannerSpec, table, "planner").model_dump()
    return Ch1Results(metrics, scenes, obstacles, settings)


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
