"""The joint limits a planner keeps, with where each came from: the record's `limits`."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from articula.planning.config import PlannerSpec
from articula.robots.limits import USER
from articula.robots.model import RobotModel

__all__ = ["kept_limits"]

# The methods whose solvers keep the speed limits even with limits = "none".
_ALWAYS_SPEED = ("qp", "pinv", "dls")


def kept_limits(spec: PlannerSpec, robot: RobotModel) -> dict[str, Any]:
    """The joint limits `spec`'s planner keeps on `robot` (planning.config.rate_limits), per
    joint, and their sources.

    A limit the planner does not keep is not listed: velocity unless limits = "none" (the
    baselines qp, pinv and dls keep it even then), acceleration only with "acceleration" in
    limits, jerk only with "jerk".

    Args:
        spec: the validated [planner] table.
        robot: the robot, its limits set from its scene file.

    Returns:
        "velocity": the speed limits times velocity_scale [rad/s or m/s]; "acceleration":
            max_acceleration for every joint when given, else the robot's [rad/s² or m/s²];
            "jerk": the robot's [rad/s³ or m/s³] (each a list per joint, None for none);
            "sources": for each listed limit, where each joint's came from ("urdf",
            "datasheet <name>", "default rule (<key> = <value> s)" or "user"; a velocity's
            source is that of the limit before velocity_scale); "datasheet": the arm's
            datasheet and how it was chosen, or None.
    """
    n = robot.nq
    kept: dict[str, tuple[np.ndarray, Sequence[str]]] = {}
    if spec.limits != "none" or spec.method in _ALWAYS_SPEED:
        speeds = spec.velocity_scale * robot.velocity_limit
        kept["velocity"] = (speeds, robot.limit_sources["velocity"])
    if "acceleration" in spec.limits:
        if spec.max_acceleration is None:
            kept["acceleration"] = (robot.acceleration_limit, robot.limit_sources["acceleration"])
        else:
            kept["acceleration"] = (np.full(n, spec.max_acceleration), (USER,) * n)
    if "jerk" in spec.limits:
        kept["jerk"] = (robot.jerk_limit, robot.limit_sources["jerk"])
    record: dict[str, Any] = {
        name: [float(v) if np.isfinite(v) and v > 0 else None for v in values]
        for name, (values, _) in kept.items()
    }
    record["sources"] = {name: list(sources) for name, (_, sources) in kept.items()}
    record["datasheet"] = robot.datasheet
    return record
