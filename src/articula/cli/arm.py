"""`articula plan` and `articula scene check`: an arm among obstacles."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import (
    Force,
    JsonFlag,
    OutDir,
    app,
    emit_json,
    out,
    print_table,
    progress_bar,
    scene_app,
)


@app.command()
def plan(
    scene_file: Annotated[
        Path, typer.Argument(help="Scene file with trajectory and planner tables (TOML).")
    ],
    out_dir: OutDir,
    force: Force = False,
    allow_collisions: Annotated[
        bool,
        typer.Option("--allow-collisions", help="Exit 0 even if a step collides (a study)."),
    ] = False,
    as_json: JsonFlag = False,
) -> None:
    """Track the scene's reference path with its planner; writes a run folder (trace + record).

    A motion with a colliding step (a link in an obstacle, or two links of a checked pair
    touching) still writes its run folder, then exits with status 4.

    \b
    Example: articula plan src/articula/book/ch1/configs/circle_two_obstacles.toml --out runs/circle
    """
    from articula.experiments.plan import load_plan
    from articula.runs.runner import run_to_folder

    with progress_bar(as_json) as bar:
        task = bar.add_task("plan", total=None)
        record = run_to_folder(
            load_plan(scene_file),
            out_dir,
            str(scene_file),
            force,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
        )
    m = record["metrics"]
    if as_json:
        emit_json(record)
    else:
        clearance = (
            "no obstacles"
            if m["min_clearance"] is None
            else (f"min clearance {m['min_clearance']:.4f} m; collisions {int(m['collisions'])}")
        )
        speed = f"{m['time_per_iteration_us']:.1f} µs per iteration"
        error = f"{1e3 * m['rms_error']:.3f} mm, max {1e3 * m['max_error']:.3f} mm"
        settled = f"after {m['settle_s']:g} s"
        if m.get("approach_s"):
            settled = (
                f"{m['settle_s']:g} s into the path (after a {m['approach_s']:.2g} s approach)"
            )
        out.print(f"RMS error {settled}: {error}; {clearance}; {speed}; written to {out_dir}")
    if m["collisions"] and not allow_collisions:
        from articula.errors import CollisionError

        raise CollisionError(
            f"the motion collides in {int(m['collisions'])} steps (deepest "
            f"{-1e3 * m['min_clearance']:.1f} mm); the run folder {out_dir} is written; pass "
            "--allow-collisions to accept it, or raise planner.d_min or lambda_weight"
        )
    if m.get("self_collisions") and not allow_collisions:
        from articula.errors import CollisionError

        raise CollisionError(
            f"the arm collides with itself in {int(m['self_collisions'])} steps (deepest "
            f"{-1e3 * m['min_self_clearance']:.1f} mm); the run folder {out_dir} is written; "
            "pass --allow-collisions to accept it, or raise robot.self_d_min"
        )


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
        typer.Option("--q-file", help="CSV or Parquet: one configuration per row [rad]."),
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
