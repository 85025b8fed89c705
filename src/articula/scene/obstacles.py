"""Obstacles: convex parts with a pose that may change with time."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from articula.errors import GeometryError
from articula.geometry.shapes import ConvexShape

PoseOfTime = Callable[[float], np.ndarray]


@dataclass(frozen=True, eq=False)
class Obstacle:
    """Named convex parts (in the obstacle frame) and the obstacle's pose in the world.

    `pose` is a 4×4 matrix, or a function of time t [s] returning one (a moving obstacle).

    Attributes:
        name: the obstacle's name, unique in a scene.
        parts: its convex parts, in the obstacle frame.
        pose: pose of the obstacle frame in the world, shape (4, 4) [m], or a function of
            time t [s] that returns it.
    """

    name: str
    parts: tuple[ConvexShape, ...]
    pose: np.ndarray | PoseOfTime

    def __post_init__(self) -> None:
        if not self.parts:
            raise GeometryError(f"obstacle {self.name!r}: has no convex parts")
        if not callable(self.pose):
            check_pose(f"obstacle {self.name!r}", self.pose)

    @property
    def moving(self) -> bool:
        """True when the pose is a function of time."""
        return callable(self.pose)

    def pose_at(self, t: float) -> np.ndarray:
        """The obstacle's pose (4×4, world) at time t [s].

        Args:
            t: time [s].

        Returns:
            The pose of the obstacle frame in the world, shape (4, 4) [m].
        """
        if callable(self.pose):
            return check_pose(f"obstacle {self.name!r}", np.asarray(self.pose(t), dtype=float))
        return self.pose


def check_pose(what: str, T: np.ndarray) -> np.ndarray:
    """T if it is a finite 4×4 pose with a rotation; GeometryError that starts with `what`
    (e.g. "obstacle 'box'"). Cheap: a live loop checks every obstacle pose every period.

    Args:
        what: what the pose belongs to, for the error message.
        T: the pose to check, shape (4, 4) [m].

    Returns:
        T itself.
    """
    if T.shape != (4, 4) or not np.isfinite(T).all():
        raise GeometryError(f"{what}: pose must be a finite 4×4 matrix (got {T.shape})")
    # det R and the entries of R Rᵀ − I, in scalars: numpy's per-call overhead would dominate.
    (a, b, c), (d, e, f), (g, h, i) = T[:3, :3].tolist()
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    gram = (
        a * a + b * b + c * c - 1.0,
        d * d + e * e + f * f - 1.0,
        g * g + h * h + i * i - 1.0,
        a * d + b * e + c * f,
        a * g + b * h + c * i,
        d * g + e * h + f * i,
    )
    if max(map(abs, gram)) > 1e-5 or det < 0:
        raise GeometryError(f"{what}: pose rotation is not a rotation matrix")
    return T
