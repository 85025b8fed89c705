"""`articula drive`: a scene's plan driving an arm in real time."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from articula.cli.app import Force, OutDir, app, out
from articula.cli.realtime import RtPriority


@app.command()
def drive(
    scene_file: Annotated[
        Path, typer.Argument(help="Scene file with trajectory and planner tables (TOML).")
    ],
    arm: Annotated[
        str,
        typer.Option(
            help="ur:HOST (a Universal Robots controller through ur-rtde, the `ur` extra) or "
            "twin (the MuJoCo twin in this process)."
        ),
    ],
    out_dir: OutDir,
    rate: Annotated[
        float, typer.Option(min=1.0, help="Servo rate [Hz]: 500 for a UR e-Series.")
    ] = 500.0,
    start_tolerance: Annotated[
        float,
        typer.Option(
            min=0.0,
            help="The farthest a joint may start from robot.q0 [rad]; beyond, nothing moves.",
        ),
    ] = 0.05,
    rt_priority: RtPriority = None,
    force: Force = False,
) -> None:
    """Drive an arm along the scene's plan in real time; writes a run folder like plan's.

    The planner runs at planner.dt, its set-points stream as servoJ at --rate, the measured
    joints close its loop. Before anything moves, the arm's joints are checked against
    robot.q0 (continuous joints the short way round): within --start-tolerance the plan
    starts where the arm is, beyond it the drive is refused (exit 2). Ctrl-C and SIGTERM
    bring the arm to rest along the stream's braking path, write the folder and exit 130 /
    143; a planner that falls behind the stream stops the arm (exit 1), as does a lost
    connection; the folder is written in every case.

    \b
    Example: articula emulate ur --scene ur10.toml &
    Example: articula drive ur10.toml --arm ur:127.0.0.1 --out runs/ur10 --rt-priority 80"""
    from articula.experiments.drive import DriveOptions
    from articula.experiments.drive import drive as run_drive
    from articula.signals import terminate_as_interrupt

    options = DriveOptions(arm, rate, start_tolerance, rt_priority)
    # Python's 5 ms GIL switch interval would let the planner's thread hold the servo thread
    # past its 2 ms tick; this process only drives, so the whole interpreter gets 0.2 ms.
    sys.setswitchinterval(2e-4)
    with terminate_as_interrupt():
        record = run_drive(scene_file, options, out_dir, force, out.print)
    m = record["metrics"]
    rms = m["plant_rms_error"]
    shown = "n/a" if rms is None else f"{1e3 * rms:.3f} mm"
    out.print(
        f"measured RMS error {shown}; deadline misses {int(m['servo_deadline_misses'])} of "
        f"{int(m['servo_releases'])} (p99 lateness {m['servo_latency_p99_ms']:.2f} ms); "
        f"written to {out_dir}",
        soft_wrap=True,
    )
