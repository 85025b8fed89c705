"""`articula view`: a planner's run in the browser."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import app, out

Port = Annotated[int, typer.Option(min=1, max=65535, help="TCP port to serve on.")]
Host = Annotated[str, typer.Option(help="Address to listen on (0.0.0.0: every interface).")]


@app.command()
def view(
    run_dir: Annotated[
        Path, typer.Argument(help="A run folder of `articula plan`, or a sweep of them.")
    ],
    port: Port = 8080,
    host: Host = "127.0.0.1",
) -> None:
    """Replay a planned run in the browser: arm, obstacles, paths, closest pair, plots.

    Example: articula view runs/circle --port 8080, then open the URL it prints."""
    from articula.viewer.replay import serve

    serve(run_dir, host, port, lambda url: out.print(f"viewer at {url} (Ctrl-C stops it)"))
