"""Targets over time: a position path with an optional orientation (fixed, or per waypoint and
interpolated) and an optional tool axis direction."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from articula.errors import ConfigError
from articula.geometry.poses import pose
from articula.planning.task import Target, unit
from articula.planning.trajectories import read_csv


@dataclass(frozen=True)
class WaypointRotations:
    """Orientations reached at increasing times [s], interpolated along the shortest rotation
    (slerp) between them and held before the first and after the last.

    Attributes:
        times: when each orientation is reached, increasing, shape (k,) [s].
        slerp: scipy's interpolator through the orientations at those times.
    """

    times: np.ndarray
    slerp: Slerp

    @classmethod
    def create(
        cls, rotations: Sequence[np.ndarray], times: Sequence[float], field: str = "rpys"
    ) -> WaypointRotations:
        """From one 3×3 rotation per time; a count that differs is a ConfigError naming `field`.

        Args:
            rotations: one rotation matrix (3×3, world) per time.
            times: when each is reached, as the waypoints' (checked there) [s].
            field: the config key named in an error.

        Returns:
            The interpolated orientations.
        """
        t = np.asarray(times, dtype=float)
        if len(rotations) != len(t):
            raise ConfigError(field, f"needs {len(t)} orientations, one per point")
        return cls(t, Slerp(t, Rotation.from_matrix(np.asarray(rotations))))

    def __call__(self, t: float) -> np.ndarray:
        """The orientation (3×3, world) at time t [s]."""
        return self.slerp(np.clip(t, self.times[0], self.times[-1])).as_matrix()


@dataclass(frozen=True)
class TargetPath:
    """Target(t): the position path's point, the orientation at t, the fixed axis.

    Attributes:
        positions: t [s] -> position [m].
        rotations: t [s] -> orientation (3×3, world); None: no orientation given.
        axis: unit world direction for the tool axis; None: none given.
        cone: [rad] how far the tool axis may be from `axis` (for the record's count).
    """

    positions: Callable[[float], np.ndarray]
    rotations: Callable[[float], np.ndarray] | None = None
    axis: np.ndarray | None = None
    cone: float | None = None

    def __call__(self, t: float) -> Target:
        """The target at time t [s]."""
        rotation = None if self.rotations is None else self.rotations(t)
        return Target(self.positions(t), rotation, self.axis)


def fixed_rotation(rotation: np.ndarray) -> Callable[[float], np.ndarray]:
    """A constant orientation as a function of time.

    Args:
        rotation: the orientation (3×3, world).

    Returns:
        A function of t [s] returning `rotation`.
    """
    return lambda t: rotation


def rotation_from(rpy: Sequence[float] | None, quaternion: Sequence[float] | None) -> np.ndarray:
    """A rotation from roll-pitch-yaw or a quaternion (the quaternion wins if both are given).

    Args:
        rpy: roll, pitch, yaw about the fixed x, y, z axes [rad]; None: use the quaternion.
        quaternion: [w, x, y, z], normalised here; None: use rpy.

    Returns:
        The rotation matrix, shape (3, 3).
    """
    if quaternion is not None:
        w, x, y, z = quaternion
        if np.linalg.norm(quaternion) < 1e-9:
            raise ConfigError("quaternion", "needs a non-zero quaternion [w, x, y, z]")
        return Rotation.from_quat([x, y, z, w]).as_matrix()
    if rpy is None:
        raise ConfigError("rpy", "give rpy = [roll, pitch, yaw] or quaternion = [w, x, y, z]")
    return pose((0.0, 0.0, 0.0), rpy)[:3, :3]  # the URDF's convention, as for obstacles


def csv_rotations(path: Path) -> WaypointRotations | None:
    """The orientations of a trajectory CSV's rows (roll, pitch, yaw or qw, qx, qy, qz columns).

    Args:
        path: the trajectory CSV file.

    Returns:
        The orientations interpolated between the rows' times, or None when it has none.
    """
    data = read_csv(path)
    names = data.dtype.names or ()
    columns = [n for n in names if n not in ("t", "x", "y", "z")]
    if columns and not all(np.all(np.isfinite(data[n])) for n in columns):
        raise ConfigError("path", f"{path}: orientation columns {columns} must be finite numbers")
    if "roll" in names:
        rotations = [rotation_from((r["roll"], r["pitch"], r["yaw"]), None) for r in data]
    elif "qw" in names:
        rotations = [rotation_from(None, (r["qw"], r["qx"], r["qy"], r["qz"])) for r in data]
    else:
        return None
    return WaypointRotations.create(rotations, data["t"], "path")


def axis_direction(axis: Sequence[float]) -> np.ndarray:
    """A tool-axis direction from the [trajectory] table as a unit vector.

    Args:
        axis: the direction in the world, any non-zero length, shape (3,).

    Returns:
        The unit direction, shape (3,).
    """
    return unit(np.asarray(axis, dtype=float), "axis")
