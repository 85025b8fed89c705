"""`articula bench suite`: articula's arm controllers beside mink on generated problems."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from articula.cli.app import (
    CORES,
    Dask,
    Force,
    JsonFlag,
    OutDir,
    Workers,
    app,
    emit_json,
    out,
    progress_bar,
)

bench_app = typer.Typer(no_args_is_help=True, help="Benchmarks of articula beside its peers.")
app.add_typer(bench_app, name="bench")


CLASS_HELP = (
    "standard; tight: obstacles 2-5 cm from the links; grazing: the links' obstacle-free "
    "motion passes within d_min of them."
)


@bench_app.command()
def suite(
    out_dir: OutDir,
    robot: Annotated[
        str,
        typer.Option(
            help="a built-in arm (iiwa14, ur5e), a URDF file, or a TOML file with a [robot] table "
            "(urdf, package_dirs, ee_frame, locked_joints, ...)."
        ),
    ] = "iiwa14",
    problems: Annotated[int, typer.Option(min=1, max=10_000, help="Generated problems.")] = 100,
    seed: Annotated[int, typer.Option(min=0, help="Seed of the problems.")] = 0,
    problem_class: Annotated[str, typer.Option("--class", help=CLASS_HELP)] = "standard",
    methods: Annotated[
        str | None,
        typer.Option(
            help="Comma-separated methods (default: every articula method, and mink "
            "and mink-matched when the peers extra is installed)."
        ),
    ] = None,
    workers: Workers = CORES,
    dask: Dask = None,
    force: Force = False,
    as_json: JsonFlag = False,
) -> None:
    """Run every method on generated tracking problems; writes results.parquet, summary.json
    and each problem as problems/NNN/scene.toml (runnable by `articula plan`).

    \b
    Example: articula bench suite --robot iiwa14 --problems 100 --out runs/suite --json
    """
    from articula.bench.problems import CLASSES
    from articula.bench.suite import choose_methods, peers_missing, run_suite
    from articula.errors import ConfigError
    from articula.runs.folders import check_out

    if problem_class not in CLASSES:
        raise ConfigError("--class", f"unknown {problem_class!r}; choose from {CLASSES}")
    missing = peers_missing()
    chosen = choose_methods(methods, missing)
    table = robot_table(robot)
    check_out(out_dir, "suite", force)
    with progress_bar(as_json) as bar:
        task = bar.add_task("suite", total=problems)
        summary = run_suite(
            table,
            problems,
            seed,
            out_dir,
            chosen,
            workers=workers,
            dask=dask,
            force=force,
            progress=lambda done, total: bar.update(task, completed=done),
            problem_class=problem_class,
        )
    summary["results"] = str(out_dir / "results.parquet")
    if missing and methods is None:
        summary["peers_skipped"] = missing
    if as_json:
        emit_json(summary)
        return
    _print(summary)


def robot_table(robot: str) -> dict[str, Any]:
    """The [robot] table of --robot: a built-in name, a URDF file or a TOML file's [robot]
    table, paths made absolute."""
    from articula.errors import ConfigError
    from articula.planning.config_files import absolute_paths
    from articula.validation import load_toml

    path = Path(robot)
    if path.suffix.lower() == ".urdf":
        if not path.is_file():
            raise ConfigError("--robot", f"no URDF file {path}")
        return {"urdf": str(path.resolve())}
    if path.suffix.lower() == ".toml":
        data = load_toml(path)
        if not isinstance(data.get("robot"), dict):
            raise ConfigError("--robot", f"{path} has no [robot] table")
        return absolute_paths({"robot": data["robot"]}, path.resolve().parent)["robot"]
    return {"builtin": robot}


def _print(summary: dict[str, Any]) -> None:
    """The summary as a table, one row per method."""
    from rich.table import Table

    table = Table(
        title=f"{summary['problems']} {summary['class']} problems, seed {summary['seed']}: "
        "success = no collision, limits kept, RMS < 1 mm after 1 s"
    )
    names = ("method", "successes", "collisions", "stalls", "mean µs", "× mink", "RMS mm")
    for name in (*names, "min clear. mm", "failures"):
        table.add_column(name, justify="left" if name in ("method", "failures") else "right")
    for method, m in summary["methods"].items():
        failures = ", ".join(f"{k} {v}" for k, v in m["failures"].items() if v) or "—"
        table.add_row(
            method,
            f"{m['successes']} ({100 * m['success_rate']:.0f} %)",
            str(m["failures"]["collision"]),
            str(m["stalls"]),
            _number(m["mean_step_us"], 0),
            _number(m.get("step_time_vs_mink"), 2),
            _number(m["median_rms_error_m"], 3, 1e3),
            _number(m["min_clearance_m"], 1, 1e3),
            failures,
        )
    out.print(table)
    if "peers_skipped" in summary:
        out.print(f"mink skipped: {summary['peers_skipped']}")
    out.print(f"results in {summary['results']}")


def _number(value: float | None, digits: int, scale: float = 1.0) -> str:
    """A number for the table, — when there is none."""
    return "—" if value is None else f"{scale * value:.{digits}f}"
