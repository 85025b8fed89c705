"""`articula reproduce ch1`: the book's tracking and obstacle-avoidance runs, and the baselines."""

from __future__ import annotations

import statistics
from collections.abc import Callable, Mapping
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from articula.experiments import records
from articula.experiments.ch1_plan import PlannerSpec, plan_data
from articula.scene.config import build_scene, load_scene_spec
from articula.scene.scene import Scene
from articula.validation import load_toml

Progress = Callable[[int, int], None]

SCENES = {
    "rectangle": "rectangle_one_obstacle.toml",
    "circle": "circle_one_obstacle.toml",
    "two obstacles": "circle_two_obstacles.toml",
}
# Faithful iterations per period that cost as many objective evaluations as baornn-improved's
# 10 × (2·3 antenna pairs + 1 step) + 1 warm start = 71: 24 × 3 = 72.
EQUAL_ITERATIONS = 24
# Table rows: name -> [planner] overrides (each scene's file gives Λ, d_min and the rest).
METHODS = {
    "baornn": {"method": "baornn"},
    "baornn-improved": {"method": "baornn-improved"},
    "baornn-equal-evaluations": {"method": "baornn", "iterations_per_step": EQUAL_ITERATIONS},
    "pinv": {"method": "pinv"},
    "dls": {"method": "dls"},
    "qp": {"method": "qp"},
}
NO_AVOIDANCE = {"lambda_weight": 0.0, "d_min": 0.0}  # Λ = 0 and no d_min: Sect. 1.4.1
STOCHASTIC = ("baornn", "baornn-improved", "baornn-equal-evaluations")
FULL_SEEDS = (0, 1, 2, 3, 4)


@dataclass(frozen=True)
class Run:
    """One planning run: a packaged scene with [planner] overrides."""

    name: str
    scene: str
    overrides: Mapping[str, Any] = field(default_factory=dict)
    title: str = ""
    book: str = ""


BOOK_RUNS = (
    Run("fig1_4_rectangle", "rectangle", NO_AVOIDANCE, "Fig. 1.4: rectangle, Λ = 0",
        "the links collide with the obstacle"),
    Run("fig1_5", "rectangle", {"lambda_weight": 0.002}, "Fig. 1.5: rectangle, Λ = 0.002",
        "no collision; accurate tracking once converged"),
    Run("fig1_6", "rectangle", {"lambda_weight": 0.0002}, "Fig. 1.6: rectangle, Λ = 0.0002",
        "no collision (d_min = 0.002); clearance much smaller than Fig. 1.5"),
    Run("fig1_4_circle", "circle", NO_AVOIDANCE, "Fig. 1.4: circle, Λ = 0",
        "the links collide with the obstacle"),
    Run("fig1_8", "circle", {"lambda_weight": 0.005}, "Fig. 1.8: circle, Λ = 0.005",
        "no collision; accurate tracking once converged"),
    Run("fig1_9", "circle", {"lambda_weight": 0.0005}, "Fig. 1.9: circle, Λ = 0.0005",
        "clearance much smaller than Fig. 1.8"),
    Run("fig1_11", "two obstacles", NO_AVOIDANCE, "Fig. 1.11: two obstacles, Λ = 0",
        "the links collide with the obstacles"),
    Run("fig1_12", "two obstacles", {"lambda_weight": 0.005},
        "Fig. 1.12: two obstacles, Λ = 0.005", "clearance stays above 0.05 m"),
)  # fmt: skip
# Each scene's book Λ is in its file; the faithful BAORNN rows reuse the book runs.
BOOK_RUN_OF_SCENE = {"rectangle": "fig1_5", "circle": "fig1_8", "two obstacles": "fig1_12"}
SNAPSHOTS = {"fig1_5": "Fig. 1.7", "fig1_8": "Fig. 1.10"}


def packaged(name: str) -> Path:
    """Path of a chapter-1 scene shipped in the package."""
    return Path(str(resources.files("articula.experiments") / "configs" / "ch1" / name))


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
                runs.append(Run(f"{_slug(scene)}_{tag}", scene, {**overrides, "seed": seed}))
    return runs


def execute(run: Run) -> tuple[dict[str, Any], dict[str, Any], dict[str, np.ndarray]]:
    """Plan one run (worker side): (config, record, trace)."""
    path = packaged(SCENES[run.scene])
    data = load_toml(path)
    # tolerance: report every result, however large its error, instead of refusing it.
    data["planner"] = {**data["planner"], **run.overrides, "tolerance": 1e3}
    config, result, wall = plan_data(data, path.parent, f"{path.name} ({run.name})")
    return config, records.build_record(config, result, wall), result.trace


def ch1_section(
    out: Path, full: bool, workers: int, progress: Progress
) -> tuple[str, dict[str, Any]]:
    """Run chapter 1 into `out`; returns its markdown and its numbers."""
    out.mkdir(parents=True, exist_ok=True)
    runs = [*BOOK_RUNS, *comparison_runs(full)]
    metrics = _run_all(runs, out / "runs", workers, lambda done: progress(done, len(runs)))
    scenes = {name: _scene(name) for name in SCENES}
    _figures(out, scenes)
    table = _comparison(metrics)
    claims = _claims(metrics, table)
    lines = _scene_lines(scenes)
    lines += _book_lines(metrics)
    lines += _comparison_lines(table, full)
    lines += ["### The chapter's claims against our runs", ""]
    lines += [
        f"- {claim}: **{'yes' if ok else 'no'}**. {why}" for claim, (ok, why) in claims.items()
    ]
    data = {
        "runs": {r.name: metrics[r.name] for r in BOOK_RUNS},
        "comparison": table,
        "claims": {claim: ok for claim, (ok, _) in claims.items()},
    }
    return "\n".join(lines), data


def _run_all(
    runs: list[Run], folder: Path, workers: int, tick: Callable[[int], None]
) -> dict[str, dict[str, float]]:
    """Plan every run (in parallel with workers > 1) and write its run folder."""
    metrics: dict[str, dict[str, float]] = {}

    def keep(run: Run, output: tuple[dict[str, Any], dict[str, Any], dict[str, np.ndarray]]):
        config, record, trace = output
        records.write_run(folder / run.name, config, record, trace)
        metrics[run.name] = record["metrics"]
        tick(len(metrics))

    if workers <= 1:
        for run in runs:
            keep(run, execute(run))
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            for run, output in zip(runs, pool.map(execute, runs), strict=True):
                keep(run, output)
    return metrics


def _scene(name: str) -> Scene:
    path = packaged(SCENES[name])
    scene, _ = build_scene(load_scene_spec(load_toml(path), str(path)), path.parent)
    return scene


def _figures(out: Path, scenes: Mapping[str, Scene]) -> None:
    from articula.viz.ch1 import paths, snapshots, time_series

    for run in BOOK_RUNS:
        trace = records.read_trace(out / "runs" / run.name)
        scene = scenes[run.scene]
        paths(scene, trace, run.title, out / f"{run.name}_paths.png")
        time_series(trace, run.title, out / f"{run.name}_series.png")
        if run.name in SNAPSHOTS:
            title = f"{SNAPSHOTS[run.name]}: snapshots, {run.title.split(': ')[1]}"
            snapshots(scene, trace, [0, 5, 15, 25, 35, 45], title,
                      out / f"{run.name}_snapshots.png")  # fmt: skip


def _comparison(metrics: Mapping[str, Mapping[str, float]]) -> dict[str, dict[str, dict]]:
    """scene -> method -> mean metrics over its seeds (and the spread of rms_error)."""
    table: dict[str, dict[str, dict]] = {}
    for scene in SCENES:
        table[scene] = {}
        for method in METHODS:
            names = [BOOK_RUN_OF_SCENE[scene]] if method == "baornn" else []
            prefix = f"{_slug(scene)}_{method}"
            names += [n for n in metrics if n == prefix or n.startswith(prefix + "_seed")]
            rows = [metrics[n] for n in names]
            keys = ("rms_error", "max_error", "min_clearance", "min_clearance_settled",
                    "collisions", "collisions_settled", "joint_limit_violations",
                    "time_per_iteration_us", "time_per_period_us")  # fmt: skip
            entry = {k: statistics.fmean(r[k] for r in rows) for k in keys}
            entry["runs"] = len(rows)
            entry["rms_error_range"] = [min(r["rms_error"] for r in rows),
                                        max(r["rms_error"] for r in rows)]  # fmt: skip
            table[scene][method] = entry
    return table


def _claims(
    m: Mapping[str, Mapping[str, float]], table: Mapping[str, Mapping[str, Mapping[str, float]]]
) -> dict[str, tuple[bool, str]]:
    """Each claim of Sect. 1.4 (and the issue's targets) with the numbers that decide it."""
    unguarded = ("fig1_4_rectangle", "fig1_4_circle", "fig1_11")
    guarded = ("fig1_5", "fig1_6", "fig1_8", "fig1_9", "fig1_12")
    mm = lambda v: f"{1e3 * v:.2f} mm"  # noqa: E731

    def improved_beats(faithful: str) -> bool:
        return all(
            table[s]["baornn-improved"]["rms_error"] < table[s][faithful]["rms_error"]
            and table[s]["baornn-improved"]["min_clearance"] >= table[s][faithful]["min_clearance"]
            for s in SCENES
        )

    def versus(faithful: str) -> str:
        return "; ".join(
            f"{s}: {mm(table[s]['baornn-improved']['rms_error'])} vs "
            f"{mm(table[s][faithful]['rms_error'])}, clearance "
            f"{mm(table[s]['baornn-improved']['min_clearance'])} vs "
            f"{mm(table[s][faithful]['min_clearance'])}"
            for s in SCENES
        )

    return {
        "Λ = 0 collides (Figs. 1.4, 1.11)": (
            all(m[n]["collisions"] > 0 for n in unguarded),
            ", ".join(f"{n}: {m[n]['collisions']:.0f} steps, deepest "
                      f"{-1e3 * m[n]['min_clearance']:.1f} mm" for n in unguarded),
        ),
        "with Λ > 0 and d_min = 0.002 m there is no collision": (
            all(m[n]["collisions"] == 0 for n in guarded),
            ", ".join(f"{n}: min clearance {mm(m[n]['min_clearance'])}" for n in guarded),
        ),
        "larger Λ keeps more clearance (Fig. 1.5 vs 1.6, 1.8 vs 1.9)": (
            m["fig1_5"]["min_clearance"] > m["fig1_6"]["min_clearance"]
            and m["fig1_8"]["min_clearance"] > m["fig1_9"]["min_clearance"],
            f"rectangle {mm(m['fig1_5']['min_clearance'])} vs "
            f"{mm(m['fig1_6']['min_clearance'])}, circle {mm(m['fig1_8']['min_clearance'])} vs "
            f"{mm(m['fig1_9']['min_clearance'])}",
        ),
        "larger Λ costs tracking accuracy (Sect. 1.4.2)": (
            m["fig1_5"]["rms_error"] > m["fig1_6"]["rms_error"]
            and m["fig1_8"]["rms_error"] > m["fig1_9"]["rms_error"],
            f"rms rectangle {mm(m['fig1_5']['rms_error'])} vs {mm(m['fig1_6']['rms_error'])}, "
            f"circle {mm(m['fig1_8']['rms_error'])} vs {mm(m['fig1_9']['rms_error'])}",
        ),
        "two obstacles: clearance above 0.05 m (Fig. 1.12)": (
            m["fig1_12"]["min_clearance"] > 0.05,
            f"min clearance {mm(m['fig1_12']['min_clearance'])} over the whole run (while "
            f"converging from q = 0), {mm(m['fig1_12']['min_clearance_settled'])} after settling",
        ),
        "Λ = 0 tracks within 1 mm RMS after settling (issue target)": (
            all(m[n]["rms_error"] <= 1e-3 for n in unguarded),
            ", ".join(f"{n}: {mm(m[n]['rms_error'])}" for n in unguarded),
        ),
        "baornn-improved beats baornn on error at equal or better clearance": (
            improved_beats("baornn"), versus("baornn"),
        ),
        "baornn-improved also beats baornn at equal objective evaluations per period": (
            improved_beats("baornn-equal-evaluations"),
            f"faithful with {EQUAL_ITERATIONS} iterations per period: "
            + versus("baornn-equal-evaluations"),
        ),
    }  # fmt: skip


def _scene_lines(scenes: Mapping[str, Scene]) -> list[str]:
    p = load_toml(packaged(SCENES["rectangle"]))["planner"]
    lines = [
        "The book gives no obstacle shapes or poses; ours (docs/deviations.md) put the obstacles "
        "in the way of the links, not of the end effector, so that only the arm's redundancy "
        f"can avoid them. Every run starts at q = 0 (the home position), control period "
        f"{1e3 * p['dt']:g} ms, {p['iterations_per_step']} BAORNN iterations per period, "
        f"c1 = {p['c1']}, c2 = {p['c2']}, β = {p['beta']}; errors are taken after a "
        f"{p['settle']:g} s settling time. Λ = 0 runs also drop the d_min constraint, as the "
        "book does (Sect. 1.4.1). Reproduce one run with `articula plan "
        "src/articula/experiments/configs/ch1/<scene>.toml --out DIR` (edit `[planner]`).",
        "",
        "| scene | file | obstacles (mesh at position [m]) |",
        "|---|---|---|",
    ]
    for name, scene in scenes.items():
        data = load_toml(packaged(SCENES[name]))
        obstacles = ", ".join(f"{o['mesh']} at {o['position']}" for o in data["obstacles"])
        names = ", ".join(o.name for o in scene.obstacles)
        lines.append(f"| {name} | `{SCENES[name]}` | {names}: {obstacles} |")
    return [*lines, ""]


def _book_lines(m: Mapping[str, Mapping[str, float]]) -> list[str]:
    lines = [
        "### Figs. 1.4-1.12: the faithful BAORNN (Algorithm 1)",
        "",
        "| run | RMS error [mm] | max error [mm] | min clearance [mm] (after settling) | "
        "colliding steps | joint-limit violations | µs per iteration | the book |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for run in BOOK_RUNS:
        r = m[run.name]
        lines.append(
            f"| {run.title} | {1e3 * r['rms_error']:.2f} | {1e3 * r['max_error']:.2f} | "
            f"{1e3 * r['min_clearance']:.1f} ({1e3 * r['min_clearance_settled']:.1f}) | "
            f"{r['collisions']:.0f} | "
            f"{r['joint_limit_violations']:.0f} | {r['time_per_iteration_us']:.0f} | {run.book} |"
        )
    lines.append("")
    for run in BOOK_RUNS:
        lines.append(f"![{run.title}](ch1/{run.name}_paths.png)")
        lines.append(f"![{run.title}: time series](ch1/{run.name}_series.png)")
        if run.name in SNAPSHOTS:
            lines.append(f"![{SNAPSHOTS[run.name]}](ch1/{run.name}_snapshots.png)")
    return [*lines, ""]


def _comparison_lines(
    table: Mapping[str, Mapping[str, Mapping[str, Any]]], full: bool
) -> list[str]:
    seeds = f"mean of seeds {FULL_SEEDS[0]}-{FULL_SEEDS[-1]}" if full else "seed 0 (quick)"
    p = PlannerSpec()
    lines = [
        "### All methods on all scenes",
        "",
        f"BAORNN rows use the scene's book Λ and d_min = 0.002 m ({seeds}); baornn-improved "
        f"uses {p.pairs} antenna pairs per iteration. pinv/dls: resolved-rate control "
        f"(K = {p.gain:g}/s) with a null-space FIRAS repulsion (η = {p.repulsion:g}, influence "
        f"{p.influence:g} m); qp: NEO-style velocity dampers (influence {p.influence:g} m, "
        f"safety {p.safety:g} m) solved by daqp. The baselines are limited to the URDF joint "
        "speeds; BAORNN, as in the book, is not. Times are of the planner alone (not the "
        "recording): per period (one control step) and per iteration (BAORNN's inner "
        "iterations; a baseline's iteration is its period).",
        "",
        "| scene | method | RMS error [mm] | max error [mm] | min clearance [mm] | "
        "after settling [mm] | colliding steps | after settling | µs per period | "
        "µs per iteration |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for scene, methods in table.items():
        for method, r in methods.items():
            lo, hi = r["rms_error_range"]
            spread = f" ({1e3 * lo:.2f}-{1e3 * hi:.2f})" if r["runs"] > 1 else ""
            lines.append(
                f"| {scene} | {method} | {1e3 * r['rms_error']:.3f}{spread} | "
                f"{1e3 * r['max_error']:.2f} | {1e3 * r['min_clearance']:.1f} | "
                f"{1e3 * r['min_clearance_settled']:.1f} | {r['collisions']:.1f} | "
                f"{r['collisions_settled']:.1f} | {r['time_per_period_us']:.0f} | "
                f"{r['time_per_iteration_us']:.0f} |"
            )
    colliding = [(s, m) for s, methods in table.items() for m, r in methods.items()
                 if r["collisions"] > 0]  # fmt: skip
    if colliding:
        late = [f"{m} on {s}" for s, m in colliding if table[s][m]["collisions_settled"] > 0]
        where = (f"after settling too: {', '.join(late)}" if late else
                 "only while the arm swings in from q = 0 (none after settling), where the "
                 "task itself drives a link at the obstacle")  # fmt: skip
        lines += ["", f"Collisions ({', '.join(f'{m} on {s}' for s, m in colliding)}): {where}."]
    return [*lines, ""]


def _slug(scene: str) -> str:
    return scene.replace(" ", "_")
