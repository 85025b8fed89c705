"""`articula` command line: parses, calls the library, prints. Errors are one line, exit 2."""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table
from typer.exceptions import Abort, Exit, TyperException

from articula.errors import ArticulaError

app = typer.Typer(add_completion=False, no_args_is_help=True, help=__doc__)
motor_app = typer.Typer(no_args_is_help=True, help="Chapter 4: DC motor model and analysis.")
app.add_typer(motor_app, name="motor")
scene_app = typer.Typer(no_args_is_help=True, help="Chapter 1: robots, obstacles and clearances.")
app.add_typer(scene_app, name="scene")
err = Console(stderr=True)
out = Console()

JsonFlag = Annotated[bool, typer.Option("--json", help="Print one JSON object and nothing else.")]
OutDir = Annotated[Path, typer.Option("--out", help="Output folder.")]


def _emit_json(obj: Any) -> None:
    """Print one JSON object on stdout; non-finite floats become null."""
    sys.stdout.write(json.dumps(_finite(obj)) + "\n")


def _finite(obj: Any) -> Any:
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite(v) for v in obj]
    return obj


def _progress(quiet: bool) -> Progress:
    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
        TimeElapsedColumn(), console=err, disable=quiet, transient=False,
    )  # fmt: skip


@app.command()
def run(
    config: Annotated[Path, typer.Argument(help="Experiment config (TOML).")],
    out_dir: OutDir,
    as_json: JsonFlag = False,
) -> None:
    """Run one experiment config and write config.toml, record.json and trace.parquet."""
    from articula.experiments.runner import run_to_folder
    from articula.validation import load_toml

    record = run_to_folder(load_toml(config), out_dir)
    if as_json:
        _emit_json(record)
        return
    table = Table(title=f"{record['experiment']} (seed {record['seed']})")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for k, v in record["metrics"].items():
        table.add_row(k, "—" if v is None else f"{v:.6g}")
    out.print(table)
    out.print(f"written to {out_dir}")


@app.command()
def sweep(
    spec: Annotated[Path, typer.Argument(help="Sweep file (TOML with base, grid, runs).")],
    out_dir: OutDir,
    workers: Annotated[
        int, typer.Option(min=1, help="Local worker processes (default: one per core).")
    ] = os.cpu_count() or 1,
    dask: Annotated[
        str | None, typer.Option(help="'local' for a loopback LocalCluster, or tcp://HOST:PORT.")
    ] = None,
    as_json: JsonFlag = False,
) -> None:
    """Run every config of a sweep, skipping finished runs; writes results.parquet."""
    from articula.experiments.records import make_folder
    from articula.experiments.runner import RESULTS, check_backend, expand_sweep, run_sweep
    from articula.validation import load_toml

    configs = expand_sweep(load_toml(spec))
    check_backend(dask)
    make_folder(out_dir)
    with _progress(as_json) as bar:
        task = bar.add_task("sweep", total=len(configs))
        table = run_sweep(
            configs, out_dir, workers=workers, dask=dask,
            progress=lambda done, total: bar.update(task, completed=done),
        )  # fmt: skip
    summary = {"runs": table.num_rows, "results": str(out_dir / RESULTS)}
    if as_json:
        _emit_json(summary)
    else:
        out.print(f"{summary['runs']} runs; results in {summary['results']}")


@app.command()
def reproduce(
    chapter: Annotated[str, typer.Argument(help="ch1, ch2, ch3, ch4 or all.")] = "all",
    out_dir: OutDir = Path("report"),
    full: Annotated[bool, typer.Option("--full", help="Full-size runs instead of quick.")] = False,
    workers: Annotated[
        int, typer.Option(min=1, help="Local worker processes (default: one per core).")
    ] = os.cpu_count() or 1,
    as_json: JsonFlag = False,
) -> None:
    """Reproduce the book's figures and tables into OUT/report.md and PNG figures."""
    from articula.experiments.records import make_folder
    from articula.experiments.reproduce import check_chapter
    from articula.experiments.reproduce import reproduce as run_reproduce

    check_chapter(chapter)
    make_folder(out_dir)
    with _progress(as_json) as bar:
        task = bar.add_task("reproduce", total=None)

        def step(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        summary = run_reproduce(chapter, out_dir, full=full, workers=workers, progress=step)
    if as_json:
        _emit_json(summary)
    else:
        out.print(f"report written to {summary['report']}")


@motor_app.command("analyze")
def motor_analyze(
    preset: Annotated[str | None, typer.Option(help="table4.1 or table4.2.")] = None,
    params: Annotated[Path | None, typer.Option(help="TOML with R, K, b, J, L (SI).")] = None,
    voltage: Annotated[float, typer.Option(help="Supply voltage V [V].")] = 12.0,
    torque: Annotated[float, typer.Option(help="External torque τ_ex [N·m].")] = 0.0,
    current: Annotated[float, typer.Option(help="Current for ω_c [A].")] = 1.0,
    as_json: JsonFlag = False,
) -> None:
    """State space (4.6), G(s) (4.7), steady state (4.8) and critical speed ω_c of a motor."""
    from articula.experiments.motor_analysis import analyze, load_params

    result = analyze(load_params(preset, params), voltage, torque, current)
    if as_json:
        _emit_json(result)
        return
    ss = result["steady_state"]
    out.print(f"A = {result['A']}\nB = {result['B']}\npoles = {result['poles']}")
    for k, tf in result["transfer"].items():
        out.print(f"{k:>13}: num {tf['num']}  den {tf['den']}")
    out.print(f"steady state at V={voltage} V, τ_ex={torque} N·m: "
              f"ω = {ss['omega']:.6g} rad/s, i = {ss['i']:.6g} A")  # fmt: skip
    if result["omega_c"] is None:
        out.print(f"ω_c: none ({result['omega_c_note']})")
    else:
        out.print(f"ω_c at V={voltage} V, i={current} A: {result['omega_c']:.6g} rad/s")


@app.command()
def plan(
    scene_file: Annotated[
        Path, typer.Argument(help="Scene file with trajectory and planner tables (TOML).")
    ],
    out_dir: OutDir,
    as_json: JsonFlag = False,
) -> None:
    """Track the scene's reference path with its planner; writes a run folder (trace + record)."""
    from articula.experiments.ch1_plan import plan_to_folder

    record = plan_to_folder(scene_file, out_dir)
    if as_json:
        _emit_json(record)
        return
    m = record["metrics"]
    out.print(f"RMS error after {m['settle_s']:g} s: {1e3 * m['rms_error']:.3f} mm, max "
              f"{1e3 * m['max_error']:.3f} mm; min clearance {m['min_clearance']:.4f} m; "
              f"collisions {int(m['collisions'])}; {m['time_per_iteration_us']:.1f} µs per "
              f"iteration; written to {out_dir}")  # fmt: skip


@scene_app.command("check")
def scene_check(
    scene_file: Annotated[
        Path, typer.Argument(help="Scene file (TOML with robot and obstacles tables).")
    ],
    q: Annotated[
        str | None, typer.Option("--q", help="Joint values q1,q2,... [rad]; default q0.")
    ] = None,
    metric: Annotated[
        str, typer.Option(help="gjk (signed convex distance) or vertex (book).")
    ] = "gjk",
    as_json: JsonFlag = False,
) -> None:
    """End-effector position and link-obstacle clearances of a scene at q0 or --q."""
    from articula.scene.check import check_scene

    result = check_scene(scene_file, q, metric)
    if as_json:
        _emit_json(result)
        return
    table = Table(title=f"{scene_file} ({metric} metric)")
    table.add_column("link")
    table.add_column("clearance [m]", justify="right")
    for name, value in result["link_clearance"].items():
        table.add_row(name, f"{value:.4f}")
    out.print(table)
    x, y, z = result["ee_position"]
    out.print(f"end-effector at ({x:.4f}, {y:.4f}, {z:.4f}) m; minimum clearance "
              f"{result['min_clearance']:.4f} m; collides: {result['collides']}")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    """Entry point: run the app; any bad input becomes one line on stderr and exit status 2."""
    try:
        app(args=argv, standalone_mode=False)
    except ArticulaError as exc:
        _fail(str(exc))
    except Exit as exc:
        sys.exit(exc.exit_code)
    except Abort:
        _fail("aborted")
    except TyperException as exc:
        message = exc.format_message().replace("\n", " ").strip()
        _fail(message or "missing command; see --help")


def _fail(message: str) -> None:
    sys.stderr.write(f"error: {message}\n")
    sys.exit(2)
