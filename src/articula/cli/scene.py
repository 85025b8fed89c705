"""`articula scene check`: a robot among obstacles, its clearances at given joint values."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import JsonFlag, emit_json, err, out, print_table, scene_app


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
    q_file: Annotated[
        Path | None,
        typer.Option(
            "--q-file",
            help="CSV or Parquet: one configuration per row [rad]; a run's trace.parquet: its "
            "q_1..q_n columns, one row per control period.",
        ),
    ] = None,
    as_json: JsonFlag = False,
) -> None:
    """End-effector position, link-obstacle clearances and self clearance of a scene at q0, --q
    or each row of --q-file.

    \b
    Example: articula scene check SCENE.toml --q "0,0.5,0,-1,0,0.6,0" --json
    """
    from articula.scene.check import check_scene

    result = check_scene(scene_file, q, metric, q_file)
    if as_json:
        emit_json(result)
        return
    if q_file is not None:
        rows = [
            (
                str(i),
                f"{r['min_clearance']:.4f}{' collides' if r['collides'] else ''}",
                f"{r['self_clearance']:.4f}{' collides' if r['self_collides'] else ''}",
            )
            for i, r in enumerate(result["configurations"])
        ]
        header = ("row", "min clearance [m]", "self clearance [m]")
        print_table(f"{scene_file} ({metric} metric)", header, rows)
        return
    if result["outside_limits"]:
        _warn_outside_limits("robot.q0" if q is None else "--q", result["outside_limits"])
    rows = [(name, f"{value:.4f}") for name, value in result["link_clearance"].items()]
    print_table(f"{scene_file} ({metric} metric)", ("link", "clearance [m]"), rows)
    x, y, z = result["ee_position"]
    out.print(
        f"end-effector at ({x:.4f}, {y:.4f}, {z:.4f}) m; minimum clearance "
        f"{result['min_clearance']:.4f} m; collides: {result['collides']}"
    )
    pair = " and ".join(result["self_closest_pair"] or ["no link pair"])
    checked = "" if result["self_collision_checked"] else " (self_collision is off)"
    out.print(
        f"self clearance {result['self_clearance']:.4f} m ({pair}); self collides: "
        f"{result['self_collides']}{checked}"
    )


def _warn_outside_limits(field: str, outside: list[dict]) -> None:
    """One line on stderr naming each joint outside its limits, its value and the limits."""
    joints = ", ".join(
        f"{o['joint']} = {o['value']:.4f} rad, outside [{o['lower']:.4f}, {o['upper']:.4f}]"
        for o in outside
    )
    # only --json leaves it out: a warning there would not be one JSON object
    err.print(
        f"warning: {field}: {joints}; plan and live refuse to start outside the joint limits",
        soft_wrap=True,
        markup=False,
        highlight=False,
    )
