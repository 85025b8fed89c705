"""`articula emulate ur`: the fake UR controller (arms.ur_fake) of a scene file's arm, served
until Ctrl-C or SIGTERM, its log of every cycle written at the end."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from articula.errors import ConfigError
from articula.experiments.plan import build_plan, load_plan

__all__ = ["serve_fake_ur"]


def serve_fake_ur(
    scene_file: Path,
    host: str,
    start: Sequence[float] | None,
    log: Path | None,
    announce: Callable[[str], None],
) -> None:
    """Serve a fake UR controller of the scene's arm until interrupted.

    Args:
        scene_file: the scene (a plan config: [robot], [[obstacles]], [plant] for the twin's
            servos).
        host: the address to listen on (the controller's ports: 29999, 30001–30004).
        start: the arm's joints at power-on [rad]; None: the scene's robot.q0.
        log: where to write the controller's log (Parquet) at the end; None: nowhere.
        announce: called with each line to show (the address, then each controller event).
    """
    from articula.arms.ur_fake.server import FakeUR
    from articula.sim.twin import ServoGains

    plan = build_plan(load_plan(scene_file), scene_file.parent, str(scene_file))
    q0 = plan.q0 if start is None else np.asarray(start, dtype=float)
    if q0.shape != plan.q0.shape:
        raise ConfigError("--start", f"needs {plan.q0.size} joint values [rad] (got {q0.size})")
    plant = plan.config.plant
    gains = None if plant is None else ServoGains(plant.stiffness, plant.damping)
    fake = FakeUR(
        plan.scene,
        q0,
        host,
        gains,
        lambda e: announce(f"t = {e.t:.3f} s: {e.text}"),
    )
    with fake:
        try:
            announce(
                f"ur controller at {host} (dashboard 29999, programs 30001-30003, RTDE 30004; "
                "Ctrl-C stops it)"
            )
            threading.Event().wait()
        finally:
            if log is not None:
                fake.write_log(log)
