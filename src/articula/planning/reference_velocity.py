"""The end-effector velocity a resolved-rate controller commands over one control period, and
the task rows (position, pose or tool axis) it is commanded through."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from articula.planning.task import Target, Task, target_arrays
from articula.validation import NonNegative, Positive, StrictModel


class RateParams(StrictModel):
    """What every resolved-rate baseline takes.

    Attributes:
        gain: K on the position error [1/s].
        influence: the distance below which an obstacle counts [m].
        speed_scale: fraction of the URDF joint velocity limits [-].
    """

    gain: NonNegative = 20.0
    influence: Positive = 0.15
    speed_scale: Positive = 1.0


def reference_velocity(
    x_ref: np.ndarray, previous_ref: np.ndarray | None, x: np.ndarray, dt: float, gain: float
) -> np.ndarray:
    """ẋ_r + K e [m/s] for the period that ends at the reference point x_ref [m].

    The feed-forward is the reference's motion over the period, (x_ref − previous_ref)/dt,
    and the feedback K [1/s] acts on the error against previous_ref, where the arm at x was
    meant to be: measuring it against x_ref as well would count the period's motion twice and
    leave a steady lag of one period's travel. Without a previous point: K (x_ref − x).

    Args:
        x_ref: reference point at the end of the period, shape (3,) [m].
        previous_ref: reference point of the previous period, shape (3,) [m]; None: none.
        x: end-effector position now, shape (3,) [m].
        dt: control period [s].
        gain: feedback gain K [1/s].

    Returns:
        The commanded end-effector velocity, shape (3,) [m/s].
    """
    if previous_ref is None:
        return gain * (x_ref - x)
    return (x_ref - previous_ref) / dt + gain * (previous_ref - x)


def task_rows(
    x: np.ndarray,
    R: np.ndarray,
    J: np.ndarray,
    task: Task,
    target: Target,
    previous: Target | None,
    dt: float,
    gain: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(J_task, v): the task Jacobian rows (rows × nq) and the velocity they should have, for
    the end effector at position x [m], rotation R with Jacobian J (6 × nq, world axes).

    Position: J_v (3 rows) and ẋ_r + K e (reference_velocity). Pose: also J_ω (3 rows) and
    ω = log(R_r R_r,prevᵀ)/dt + K log(R_r,prev Rᵀ), the same feed-forward and feedback on the
    rotation (world axes). Position+axis: the two rows of J_ω across the tool axis a, and
    there the rotation that takes a to the reference axis (its feed-forward likewise).

    Args:
        x: end-effector position, shape (3,) [m].
        R: end-effector rotation in the world, shape (3, 3).
        J: end-effector Jacobian, world axes, linear rows first, shape (6, nq).
        task: what the end effector tracks.
        target: the target at the end of the period.
        previous: the previous period's target; None: no feed-forward.
        dt: control period [s].
        gain: feedback gain K [1/s].

    Returns:
        The task Jacobian, shape (rows, nq) (rows 3, 6 or 5), and its commanded velocity,
        shape (rows,) [m/s, then rad/s].
    """
    v = reference_velocity(
        target.position, None if previous is None else previous.position, x, dt, gain
    )
    if task.kind == "position":
        return J[:3], v
    rotation, axis = target_arrays(task, target)
    if task.kind == "pose":
        if previous is None:
            w = gain * pin.log3(rotation @ R.T)
        else:
            before = target_arrays(task, previous)[0]
            w = pin.log3(rotation @ before.T) / dt + gain * pin.log3(before @ R.T)
        return np.vstack([J[:3], J[3:]]), np.r_[v, w]
    a = R @ task.tool_axis
    if previous is None:
        w = gain * rotation_vector(a, axis)
    else:
        before = target_arrays(task, previous)[1]
        w = rotation_vector(before, axis) / dt + gain * rotation_vector(a, before)
    across = _across(a)  # spin about a itself leaves the axis where it is: not a task row
    return np.vstack([J[:3], across @ J[3:]]), np.r_[v, across @ w]


def rotation_vector(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation vector of the shortest rotation taking unit vector a to b.

    Args:
        a: unit vector the rotation starts from, shape (3,).
        b: unit vector it ends at, shape (3,).

    Returns:
        The axis times the angle, shape (3,) [rad]; zero when a and b are (anti)parallel.
    """
    cross = np.cross(a, b)
    sine = float(np.linalg.norm(cross))
    angle = math.atan2(sine, float(a @ b))
    if sine < 1e-12:
        return np.zeros(3)  # aligned (or exactly opposite: no unique shortest rotation)
    return cross / sine * angle


def _across(a: np.ndarray) -> np.ndarray:
    """Two orthonormal rows perpendicular to unit vector a (2 × 3)."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(a, helper)
    u /= np.linalg.norm(u)
    return np.vstack([u, np.cross(a, u)])
