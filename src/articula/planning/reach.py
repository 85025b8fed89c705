"""Refuse a reference path that leaves the arm's reach before planning along it."""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from articula.errors import InfeasibleError
from articula.robots.model import RobotModel

# Pinocchio's joints that only rotate about their origin: revolute about an axis, unaligned,
# unbounded (continuous), spherical.
ROTATING = frozenset({
    "JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned",
    "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned",
    "JointModelSpherical", "JointModelSphericalZYX",
})  # fmt: skip


def reach_sphere(robot: RobotModel) -> tuple[np.ndarray, float] | None:
    """(centre [m], radius [m]) of a sphere containing every end-effector position, or None.

    For a chain of revolute joints, the distance between successive joint origins (and from
    the last joint to the end effector) is fixed, so the end effector stays within their sum
    of the first joint's origin. A joint that translates (prismatic along an axis, PX/PY/PZ,
    or unaligned; planar; free) has no such bound.

    Args:
        robot: the arm, its end-effector frame included.

    Returns:
        The first joint's origin, shape (3,) [m], and the reach radius [m]; None when a
        joint translates.
    """
    model, data = robot.model, robot.model.createData()
    if not all(joint.shortname() in ROTATING for joint in model.joints[1:]):
        return None
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    points = [data.oMi[j].translation for j in range(1, model.njoints)]
    points.append(data.oMf[robot.ee_frame_id].translation)
    radius = sum(float(np.linalg.norm(b - a)) for a, b in itertools.pairwise(points))
    return points[0].copy(), radius


def check_reach(
    robot: RobotModel, trajectory: Callable[[float], np.ndarray], duration: float
) -> None:
    """InfeasibleError naming the first sampled time [s] at which the path is out of reach.

    The path is sampled at 2001 times over [0, duration]; an arm with a translating joint is
    not checked.

    Args:
        robot: the arm, its end-effector frame included.
        trajectory: reference position at time t, t [s] -> shape (3,) [m].
        duration: length of the run [s].
    """
    sphere = reach_sphere(robot)
    if sphere is None:
        return
    centre, radius = sphere
    for t in np.linspace(0.0, duration, 2001):
        distance = float(np.linalg.norm(trajectory(t) - centre))
        if distance > radius:
            raise InfeasibleError(
                f"unreachable: at t = {t:.2f} s the path is {distance:.3f} m from the first "
                f"joint, beyond the arm's reach of {radius:.3f} m (the error cannot fall below "
                f"{distance - radius:.3g} m)",
                "trajectory",
            )
