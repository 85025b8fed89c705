"""The first run's notice: a command that compiles the kernels from scratch says so."""

from __future__ import annotations

from rich.console import Console

# Commands whose first run compiles the numba kernels (about a minute on a fresh install).
COMPILING = frozenset({"plan", "run", "sweep", "live", "view", "drive", "reproduce", "bench"})


def notice(command: str | None, console: Console) -> None:
    """Tell the person waiting that `command` compiles the kernels first, if it will.

    Args:
        command: the subcommand about to run (None: none).
        console: where to say it (stderr).
    """
    if command in COMPILING:
        from articula.numba_cache import is_cold

        if is_cold():
            console.print(
                "compiling articula's kernels once (about a minute); later runs load them"
            )
