"""Rigid poses as 4×4 homogeneous matrices, with URDF's roll-pitch-yaw convention."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from articula.errors import GeometryError


def rotation_rpy(rpy: Sequence[float]) -> np.ndarray:
    """Rotation matrix for fixed-axis roll, pitch, yaw [rad]: R = Rz(yaw)·Ry(pitch)·Rx(roll).

    Args:
        rpy: roll, pitch and yaw angles, shape (3,) [rad].

    Returns:
        The rotation matrix, shape (3, 3).
    """
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def pose(
    position: Sequence[float] = (0.0, 0.0, 0.0), rpy: Sequence[float] = (0.0, 0.0, 0.0)
) -> np.ndarray:
    """4×4 pose from a position [m] and roll-pitch-yaw angles [rad].

    Args:
        position: translation x, y, z, shape (3,) [m].
        rpy: roll, pitch and yaw angles (URDF convention), shape (3,) [rad].

    Returns:
        The homogeneous transform, shape (4, 4).
    """
    xyz = np.asarray(position, dtype=float)
    angles = np.asarray(rpy, dtype=float)
    if xyz.shape != (3,) or angles.shape != (3,):
        raise GeometryError(
            f"pose: position and rpy need 3 numbers each (got {xyz.shape}, {angles.shape})"
        )
    if not (np.all(np.isfinite(xyz)) and np.all(np.isfinite(angles))):
        raise GeometryError("pose: position and rpy must be finite numbers")
    T = np.eye(4)
    T[:3, :3] = rotation_rpy(angles)
    T[:3, 3] = xyz
    return T


def transform_points(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply the pose T to an (n, 3) array of points.

    Args:
        T: homogeneous transform, shape (4, 4).
        points: points in the frame T maps from, shape (n, 3) [m].

    Returns:
        The transformed points, shape (n, 3) [m].
    """
    return points @ T[:3, :3].T + T[:3, 3]
