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
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

HELP = "`articula` command line: parses, calls the library, prints. Errors are one line, exit 2."
app = typer.Typer(add_completion=False, no_args_is_help=True, help=HELP)
motor_app = typer.Typer(no_args_is_help=True, help="Chapter 4: DC motor model and analysis.")
app.add_typer(motor_app, name="motor")
scene_app = typer.Typer(no_args_is_help=True, help="Chapter 1: robots, obstacles and clearances.")
app.add_typer(scene_app, name="scene")
err = Console(stderr=True)
out = Console()

JsonFlag = Annotated[bool, typer.Option("--json", help="Print one JSON object and nothing else.")]
OutDir = Annotated[Path, typer.Option("--out", help="Output folder.")]
CORES = os.cpu_count() or 1  # default number of local worker processes
MAX_WORKERS = 1024  # more would only queue
Workers = Annotated[
    int,
    typer.Option(min=1, max=MAX_WORKERS, help="Local worker processes (default: one per core)."),
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


def print_table(title: str, columns: tuple[str, str], rows: list[tuple[str, str]]) -> None:
    """A two-column table on stdout, values right-aligned."""
    from rich.markup import escape  # "[m]" is a unit, not rich markup

    table = Table(title=escape(title))
    table.add_column(escape(columns[0]))
    table.add_column(escape(columns[1]), justify="right")
    for row in rows:
        table.add_row(*(escape(cell) for cell in row))
    out.print(table)


def progress_bar(quiet: bool) -> Progress:
    """A progress bar on stderr while work runs; none with --json or without a terminal (a
    log or a pipe would only collect its frames), and it leaves no line behind, so that an
    error that ends the work stays the only line."""
    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
        TimeElapsedColumn(), console=err, disable=quiet or not err.is_terminal, transient=True,
    )  # fmt: skip
