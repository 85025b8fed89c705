"""A reachable start: the reference moves from the tool to the path's start, then the path
begins (beyond the book, whose runs start the path at once wherever the tool is)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from articula.planning.task import Target, as_target

Trajectory = Callable[[float], "np.ndarray | Target"]  # a position [m] or a whole Target
NEAR = 1e-3  # [m] a path that starts this close to the tool needs no approach
NEAR_ANGLE = 1e-3  # [rad] nor one whose start orientation is this close to the tool's
PEAK = 15.0 / 8.0  # peak speed of a minimum-jerk motion over its mean speed


@dataclass(frozen=True)
class Approach:
    """The reference over a run: for `duration` [s] from the tool's start to the path's start
    along a straight line with a minimum-jerk pace (at rest at both ends, orientation by slerp,
    tool axis turned about their common normal), then the path, `duration` later.

    Attributes:
        path: the path, t [s] from its own start -> position (3,) [m] or Target.
        start: the tool at the start: position [m], orientation and tool axis (world).
        duration: the approach's length [s]; 0: the path begins at once.
    """

    path: Trajectory
    start: Target
    duration: float

    def __call__(self, t: float) -> Target:
        """The target at run time t [s]."""
        if t >= self.duration:
            return as_target(self.path(t - self.duration))
        goal = as_target(self.path(0.0))
        u = t / self.duration
        s = u**3 * (10.0 + u * (-15.0 + 6.0 * u))  # minimum-jerk pace, 0 → 1
        position = self.start.position + s * (goal.position - self.start.position)
        rotation = None
        if goal.rotation is not None and self.start.rotation is not None:
            both = Rotation.from_matrix(np.array([self.start.rotation, goal.rotation]))
            rotation = Slerp([0.0, 1.0], both)(s).as_matrix()
        axis = None
        if goal.axis is not None and self.start.axis is not None:
            axis = _turn(self.start.axis, goal.axis, s)
        return Target(position, rotation, axis)


def approach(path: Trajectory, start: Target, speed: float, turn_rate: float) -> Approach:
    """The approach from the tool to a path's start, as long as its distance at `speed` [m/s]
    and its turn at `turn_rate` [rad/s] (peak values) need; none when the path starts at the
    tool.

    Args:
        path: the path, t [s] -> position (3,) [m] or Target.
        start: the tool at the start: position [m], orientation and tool axis (world).
        speed: the approach's peak tool speed [m/s].
        turn_rate: the approach's peak tool turn rate [rad/s] (for an orientation or axis the
            path gives).

    Returns:
        The reference over the whole run, with its approach's duration [s].
    """
    goal = as_target(path(0.0))
    distance = float(np.linalg.norm(goal.position - start.position))
    angle = 0.0
    if goal.rotation is not None and start.rotation is not None:
        angle = float(Rotation.from_matrix(start.rotation.T @ goal.rotation).magnitude())
    elif goal.axis is not None and start.axis is not None:
        angle = _angle(start.axis, goal.axis)
    if distance <= NEAR and angle <= NEAR_ANGLE:
        return Approach(path, start, 0.0)
    return Approach(path, start, PEAK * max(distance / speed, angle / turn_rate))


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle between two unit vectors [rad]."""
    return math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b))


def _turn(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Unit vector a turned toward unit vector b by the fraction s of the angle between them."""
    angle = _angle(a, b)
    if angle < 1e-12:
        return b.copy()
    normal = np.cross(a, b)
    if np.linalg.norm(normal) < 1e-12:  # opposite: any perpendicular axis turns a onto b
        normal = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])
    return Rotation.from_rotvec(s * angle * normal / np.linalg.norm(normal)).apply(a)
