"""The `articula` app, its sub-apps, shared options and output helpers."""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

HELP = """Control and decision-making for articulated robots and their soft end-effectors.

articula tracks task-space paths with redundant arms (any URDF) around obstacles, controls soft
bending and six-chamber actuators and DC-motor current, reproduces the book's experiments and
drives the bench rigs over serial. The three most common commands:

\b
  articula reproduce all --out report            # the book's figures and tables, quick mode
  articula plan SCENE.toml --out runs/circle      # an arm tracks a path around obstacles
  articula run CONFIG.toml --out runs/fuzzy       # one experiment of chapters 2-4

Errors are one line on stderr with an exit status: 2 bad input, 1 the machine, 3 a bug.
Documentation: docs/ (mkdocs serve), examples: examples/.
"""
app = typer.Typer(add_completion=False, no_args_is_help=True, help=HELP, rich_markup_mode=None)
motor_app = typer.Typer(no_args_is_help=True, help="Chapter 4: DC motor model and analysis.")
app.add_typer(motor_app, name="motor")
scene_app = typer.Typer(no_args_is_help=True, help="Chapter 1: robots, obstacles and clearances.")
app.add_typer(scene_app, name="scene")
err = Console(stderr=True)
out = Console()

JsonFlag = Annotated[bool, typer.Option("--json", help="Print one JSON object and nothing else.")]
OutDir = Annotated[Path, typer.Option("--out", metavar="FOLDER", help="Output folder.")]
CORES = os.cpu_count() or 1  # default number of local worker processes
MAX_WORKERS = 1024  # more would only queue
Workers = Annotated[
    int,
    typer.Option(
        min=1,
        max=MAX_WORKERS,
        show_default=False,
        help="Local worker processes (default: one per core).",
    ),
]
Force = Annotated[
    bool,
    typer.Option(
        "--force", help="Write into a folder that holds other files (only ours are replaced)."
    ),
]
Dask = Annotated[
    str | None, typer.Option(help="'local' for a loopback LocalCluster, or tcp://HOST:PORT.")
]


def _print_version(wanted: bool) -> None:
    """Print articula's version and stop (the eager --version option)."""
    if wanted:
        from articula import __version__

        out.print(f"articula {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    ctx: typer.Context,
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_print_version, is_eager=True, help="Print the version."
        ),
    ] = False,
) -> None:
    """The options of `articula` itself."""
    if err.is_terminal:  # a person waits, not a log
        from articula.cli.first_run import notice

        notice(ctx.invoked_subcommand, err)


def emit_json(obj: Any) -> None:
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


def print_table(title: str, columns: tuple[str, ...], rows: list[tuple[str, ...]]) -> None:
    """A table on stdout: names in the first column, values right-aligned in the others."""
    from rich.markup import escape  # "[m]" is a unit, not rich markup

    table = Table(title=escape(title))
    table.add_column(escape(columns[0]))
    for column in columns[1:]:
        table.add_column(escape(column), justify="right")
    for row in rows:
        table.add_row(*(escape(cell) for cell in row))
    out.print(table)


def metric_rows(metrics: dict[str, float | str | None]) -> list[tuple[str, str]]:
    """A record's metrics as table rows, six significant digits (a name as it is), — where
    there is none."""
    return [
        (k, "—" if v is None else v if isinstance(v, str) else f"{v:.6g}")
        for k, v in metrics.items()
    ]


def progress_bar(quiet: bool) -> Progress:
    """A progress bar on stderr while work runs; none with --json or without a terminal (a
    log or a pipe would only collect its frames), and it leaves no line behind, so that an
    error that ends the work stays the only line."""
    return Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=err,
        disable=quiet or not err.is_terminal,
        transient=True,
    )
