"""`articula view`: a planner's run in the browser."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import Force, app, out

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

    Open the URL it prints; Ctrl-C stops it.

    \b
    Example: articula view runs/circle --port 8080"""
    from articula.viewer.replay import serve

    serve(run_dir, host, port, lambda url: out.print(f"viewer at {url} (Ctrl-C stops it)"))


@app.command()
def live(
    scene: Annotated[Path, typer.Argument(help="A scene file with [trajectory] and [planner].")],
    method: Annotated[
        str | None,
        typer.Option(help="baornn, baornn-improved, pinv, dls or qp (default: the file's)."),
    ] = None,
    port: Port = 8080,
    host: Host = "127.0.0.1",
    record: Annotated[
        Path | None,
        typer.Option(metavar="FOLDER", help="Write what happened as a run folder `view` replays."),
    ] = None,
    plant: Annotated[
        str | None,
        typer.Option(
            help="mujoco: drive the MuJoCo twin (the sim extra) and close the loop on its "
            "measured joints; none: the arm is where it was told (default: the file's [plant])."
        ),
    ] = None,
    force: Force = False,
) -> None:
    """Run the scene's planner in real time in the browser; drag obstacles and the target.

    \b
    Example: articula live src/articula/book/ch1/configs/circle_two_obstacles.toml --method qp
    With the arm's dynamics: ... --plant mujoco (the measured arm drawn in blue)"""
    from articula.errors import ConfigError
    from articula.planning.config import METHODS
    from articula.runs.folders import check_out
    from articula.viewer.live import run_live
    from articula.viewer.live_scene import PLANTS

    if method is not None and method not in METHODS:
        raise ConfigError(
            "--method", f"unknown method {method!r}; choose one of {', '.join(METHODS)}"
        )
    if plant is not None and plant not in PLANTS:
        raise ConfigError("--plant", f"unknown plant {plant!r}; choose one of {', '.join(PLANTS)}")
    if record is not None:
        check_out(record, "run", force, option="--record")
    run_live(
        scene,
        method,
        host,
        port,
        record,
        lambda url: out.print(f"live at {url} (Ctrl-C stops it)"),
        plant,
    )
