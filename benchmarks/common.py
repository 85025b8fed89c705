"""What every benchmark script shares: `--json`, or a table of its measures for a person."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Sequence
from typing import Any

Rows = Sequence[Sequence[str]]


def run(
    doc: str,
    measure: Callable[..., dict[str, Any]],
    table: Callable[[dict[str, Any]], tuple[str, Sequence[str], Rows]],
    **options: dict[str, Any],
) -> None:
    """Parse the command line, measure, and print one JSON object (--json) or a rich table.

    Args:
        doc: the script's docstring; its first line is the --help description.
        measure: called with the parsed `options` as keyword arguments; returns the measures.
        table: measures -> (title, column names, rows of cells).
        options: extra command-line options, name -> argparse keyword arguments
            (`workers={"type": int, "default": 2, "help": "..."}` adds --workers).
    """
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    for name, kwargs in options.items():
        parser.add_argument(f"--{name.replace('_', '-')}", dest=name, **kwargs)
    args = parser.parse_args()
    m = measure(**{name: getattr(args, name) for name in options})
    if args.json:
        print(json.dumps(m))
        return
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    title, columns, rows = table(m)
    out = Table(title=escape(title))
    for column in columns:
        out.add_column(escape(column))
    for row in rows:
        out.add_row(*(escape(cell) for cell in row))  # "[s]" is a unit, not rich markup
    Console().print(out)
