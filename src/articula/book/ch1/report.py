"""Chapter 1's report section: formats the runs, the comparison and the figures; no computing."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from articula.book.ch1.analysis import Metrics, Table, colliding_methods
from articula.book.ch1.book_values import BOOK_RUNS, FULL_SEEDS, SCENES, SNAPSHOTS
from articula.book.ch1.study import SWEEP, Ch1Results


def markdown(results: Ch1Results, table: Table, full: bool) -> str:
    """The section: the scenes, the book's runs with their figures, the comparison."""
    p = results.settings
    lines = _scene_lines(results.obstacles, p) + _book_lines(results.metrics)
    return "\n".join(lines + _comparison_lines(table, full, p))


def _scene_lines(
    obstacles: Mapping[str, list[tuple[str, str, list[float]]]], p: Mapping[str, Any]
) -> list[str]:
    lines = [
        "The book gives no obstacle shapes or poses; ours (docs/deviations.md) put the obstacles "
        "in the way of the links, not of the end effector, so that only the arm's redundancy "
        f"can avoid them. Every run starts at q = 0 (the home position), control period "
        f"{1e3 * p['dt']:g} ms, {p['iterations_per_step']} BAORNN iterations per period, "
        f"c1 = {p['c1']}, c2 = {p['c2']}, β = {p['beta']}; errors are taken after a "
        f"{p['settle']:g} s settling time. Λ = 0 runs also drop the d_min constraint, as the "
        "book does (Sect. 1.4.1). Reproduce one run with `articula plan "
        "src/articula/book/ch1/configs/<scene>.toml --out DIR` (edit `[planner]`), or the "
        f"whole study with `articula sweep ch1/{SWEEP} --out DIR` (the sweep file is written "
        "beside this report).",
        "",
        "| scene | file | obstacles (mesh at position [m]) |",
        "|---|---|---|",
    ]
    for name, items in obstacles.items():
        names = ", ".join(n for n, _, _ in items)
        where = ", ".join(f"{mesh} at {position}" for _, mesh, position in items)
        lines.append(f"| {name} | `{SCENES[name]}` | {names}: {where} |")
    return [*lines, ""]


def _book_lines(m: Metrics) -> list[str]:
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


def _comparison_lines(table: Table, full: bool, p: Mapping[str, Any]) -> list[str]:
    seeds = f"mean of seeds {FULL_SEEDS[0]}-{FULL_SEEDS[-1]}" if full else "seed 0 (quick)"
    lines = [
        "### All methods on all scenes",
        "",
        f"BAORNN rows use the scene's book Λ and d_min = {p['d_min']:g} m ({seeds}); "
        f"baornn-improved uses {p['pairs']} antenna pairs per iteration, every second one "
        f"{p['short_antenna']:g} as long. pinv/dls: resolved-rate "
        f"control (K = {p['gain']:g}/s) with a null-space FIRAS repulsion (η = "
        f"{p['repulsion']:g}, influence {p['influence']:g} m); qp: NEO-style velocity dampers "
        f"(influence {p['influence']:g} m, safety {p['safety']:g} m) solved by daqp. The "
        "baselines are limited to the URDF joint speeds; BAORNN, as in the book, is not "
        '(`limits = "none"`; `articula plan` applies the speed limits by default). '
        "Times are of the planner alone (not the recording): per period (one control step) "
        "and per iteration (BAORNN's inner iterations; a baseline's iteration is its period).",
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
    colliding = colliding_methods(table)
    if colliding:
        late = [f"{m} on {s}" for s, m in colliding if table[s][m]["collisions_settled"] > 0]
        where = (
            f"after settling too: {', '.join(late)}"
            if late
            else "only while the arm swings in from q = 0 (none after settling), where the "
            "task itself drives a link at the obstacle"
        )
        lines += ["", f"Collisions ({', '.join(f'{m} on {s}' for s, m in colliding)}): {where}."]
    return [*lines, ""]
