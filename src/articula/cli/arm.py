"""`articula plan`: an arm tracking a path among obstacles."""

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
    progress_bar,
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
    servo_rate: Annotated[
        float | None,
        typer.Option("--servo-rate", help="Also write servo.parquet: the stream at HZ [Hz]."),
    ] = None,
    as_json: JsonFlag = False,
) -> None:
    """Track the scene's reference path with its planner; writes a run folder (trace + record).

    A motion with a colliding step (a link in an obstacle, or two links of a checked pair
    touching), or one the dynamics twin ([plant]) touches something in, still writes its run
    folder, then exits with status 4; one that does not track its path (planner.tolerance,
    max_error_tolerance) writes it and exits with status 2, naming the cause measured (a stall
    at a boundary, a start no step could leave, ...), as does a servo stream that passes below
    a clearance floor, or a twin that holds a joint at its effort limit, passes below a floor
    or strays from the path (docs/guides/servo.md). The line printed gives the errors, the
    clearance, and with a stream or a twin their key ratios.

    \b
    Example: articula plan src/articula/book/ch1/configs/circle_two_obstacles.toml --out runs/circle
    """
    from articula.experiments.plan import load_plan
    from articula.runs.runner import run_to_folder

    with progress_bar(as_json) as bar:
        task = bar.add_task("plan", total=None)
        record = run_to_folder(
            load_plan(scene_file, servo_rate),
            out_dir,
            str(scene_file),
            force,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
        )
    m = record["metrics"]
    if as_json:
        emit_json(record)
    else:
        out.print(f"{_summary(m)}; written to {out_dir}")
    if not m.get("tracked", True):
        from articula.errors import InfeasibleError

        why = record["not_tracked"]
        raise InfeasibleError(f"{why}; the run folder {out_dir} is written", f"{scene_file}")
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
    if m.get("plant_contacts") and not allow_collisions:
        from articula.errors import CollisionError

        raise CollisionError(
            f"the twin's arm touched an obstacle or itself in {int(m['plant_contacts'])} "
            f"periods (MuJoCo's contacts); the run folder {out_dir} is written; pass "
            "--allow-collisions to accept it, or raise planner.d_min or the plant's stiffness"
        )


def _summary(m: dict) -> str:
    """The run's line: errors, clearance, stall, the stream's ratios and clipped set-points
    and the twin's error, torque ratio and contacts (those the record has), the planner's time
    per iteration."""
    settled = f"after {m['settle_s']:g} s"
    if m.get("approach_s"):
        settled = f"{m['settle_s']:g} s into the path (after a {m['approach_s']:.2g} s approach)"
    parts = [
        f"RMS error {settled}: {1e3 * m['rms_error']:.3f} mm, max {1e3 * m['max_error']:.3f} mm"
    ]
    if m["min_clearance"] is None:
        parts.append("no obstacles")
    else:
        parts.append(f"min clearance {m['min_clearance']:.4f} m; collisions {int(m['collisions'])}")
    if m.get("stalled_s"):
        parts.append(f"stalled {m['stalled_s']:.2f} s")
    if "servo_max_jerk_ratio" in m:
        parts.append(
            f"servo at {m['servo_max_acceleration_ratio']:.2f} of the acceleration and "
            f"{m['servo_max_jerk_ratio']:.2f} of the jerk limits, "
            f"{m['servo_max_velocity_ratio']:.2f} of the speed limits, "
            f"{int(m['servo_clipped'])} set-points clipped"
        )
    if "plant_rms_error" in m:
        parts.append(
            f"twin: RMS error {1e3 * m['plant_rms_error']:.3f} mm, torque at "
            f"{m['max_torque_ratio']:.2f} of the effort limits, contacts in "
            f"{int(m['plant_contacts'])} periods"
        )
    return "; ".join([*parts, f"{m['time_per_iteration_us']:.1f} µs per iteration"])
