"""What the end effector is asked to do each period: a position, and optionally an orientation
or a tool axis (beyond the book, whose task is the position alone, Eq. 1.5)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from articula.errors import ConfigError
from articula.numba_cache import jit

TaskKind = Literal["position", "pose", "position+axis"]
KIND_CODES: dict[str, int] = {"position": 0, "pose": 1, "position+axis": 2}  # for the kernels


@dataclass(frozen=True)
class Target:
    """One period's reference for the end effector.

    Attributes:
        position: reference position, shape (3,) [m].
        rotation: rotation of the tool frame (3×3, world) for a pose task; None: held from
            the start (see OnlineController.reset).
        axis: unit world direction of the tool axis for a position+axis task, shape (3,);
            None: held from the start.
    """

    position: np.ndarray
    rotation: np.ndarray | None = None
    axis: np.ndarray | None = None


@dataclass(frozen=True)
class Task:
    """The task kind and how its orientation part is weighed.

    Attributes:
        kind: "position" (the book's), "pose" (position and orientation) or "position+axis"
            (position, and the tool axis along a direction).
        weight: [m/rad] BAORNN's objective adds weight · orientation error to the position
            error; the baselines track the orientation rows exactly and ignore it.
        tool_axis: the tool axis in the end-effector frame (unit vector).
    """

    kind: TaskKind = "position"
    weight: float = 0.1
    tool_axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))

    def __post_init__(self) -> None:
        if self.kind not in KIND_CODES:
            raise ConfigError("task", f"unknown task {self.kind!r}; choose {sorted(KIND_CODES)}")
        if not (math.isfinite(self.weight) and self.weight >= 0):
            raise ConfigError("orientation_weight", f"must be finite and >= 0 (got {self.weight})")
        object.__setattr__(self, "tool_axis", unit(self.tool_axis, "tool_axis"))

    @property
    def code(self) -> int:
        """The kind as the kernels' integer."""
        return KIND_CODES[self.kind]

    def orientation_error(self, rotation: np.ndarray, target: Target) -> float:
        """The orientation error [rad] of a tool frame with `rotation` (3×3, world): the angle
        of the rotation between it and the target's (pose), the angle between the tool axis
        and the target's axis (position+axis), 0 for a position task.

        Args:
            rotation: the tool frame's rotation (3×3, world).
            target: the target whose rotation or axis is the reference.

        Returns:
            The orientation error [rad].
        """
        reference = target_arrays(self, target)
        return orientation_error(self.code, self.tool_axis, rotation, *reference)


def as_target(target: Target | np.ndarray) -> Target:
    """A Target as is; a position [m] as the Target of that position alone.

    Args:
        target: a Target, or a position, shape (3,) [m].

    Returns:
        The Target.
    """
    return target if isinstance(target, Target) else Target(np.asarray(target, dtype=float))


def unit(vector: np.ndarray | list[float], field_name: str) -> np.ndarray:
    """`vector` as a unit 3-vector; ConfigError naming `field_name` for a zero or bad one.

    Args:
        vector: a non-zero 3-vector.
        field_name: the config key named in an error.

    Returns:
        The unit vector, shape (3,).
    """
    v = np.asarray(vector, dtype=float)
    norm = float(np.linalg.norm(v)) if v.shape == (3,) else 0.0
    if not (math.isfinite(norm) and norm > 1e-9):
        raise ConfigError(field_name, f"needs a non-zero 3-vector (got {np.asarray(vector)})")
    return v / norm


def target_arrays(task: Task, target: Target) -> tuple[np.ndarray, np.ndarray]:
    """(reference rotation, reference axis) of a target as arrays for the kernels; the one the
    task does not use is a placeholder. ConfigError when the task needs one the target lacks.

    Args:
        task: the task, whose kind says which reference is needed.
        target: the period's target.

    Returns:
        The reference rotation, shape (3, 3), and the reference axis, shape (3,).
    """
    rotation = np.eye(3) if target.rotation is None else target.rotation
    axis = task.tool_axis if target.axis is None else target.axis
    if task.kind == "pose" and target.rotation is None:
        raise ConfigError("target", "a pose task needs a target orientation")
    if task.kind == "position+axis" and target.axis is None:
        raise ConfigError("target", "a position+axis task needs a target axis")
    return np.ascontiguousarray(rotation, dtype=float), np.ascontiguousarray(axis, dtype=float)


@jit()
def orientation_error(
    kind: int, tool_axis: np.ndarray, R: np.ndarray, R_ref: np.ndarray, axis_ref: np.ndarray
) -> float:
    """Orientation error of rotation R against the reference (see Task).

    Args:
        kind: the task's code: 0 position, 1 pose, 2 position+axis.
        tool_axis: the tool axis in the end-effector frame, shape (3,).
        R: the tool frame's rotation (3×3, world).
        R_ref: reference rotation (3×3, world), used by a pose task.
        axis_ref: reference unit axis in the world, shape (3,), used by a position+axis task.

    Returns:
        The angle between R and R_ref (pose), or between the tool axis and axis_ref
        (position+axis), 0 for a position task [rad].
    """
    if kind == 1:
        # The angle of R_refᵀ R from its trace; atan2 of the skew part keeps it exact near 0.
        trace = 0.0
        for i in range(3):
            trace += R_ref[0, i] * R[0, i] + R_ref[1, i] * R[1, i] + R_ref[2, i] * R[2, i]
        # M = R_refᵀ R; its skew part (M − Mᵀ)/2 has norm sin θ.
        m01 = m10 = m02 = m20 = m12 = m21 = 0.0
        for k in range(3):
            m01 += R_ref[k, 0] * R[k, 1]
            m10 += R_ref[k, 1] * R[k, 0]
            m02 += R_ref[k, 0] * R[k, 2]
            m20 += R_ref[k, 2] * R[k, 0]
            m12 += R_ref[k, 1] * R[k, 2]
            m21 += R_ref[k, 2] * R[k, 1]
        sx, sy, sz = (m21 - m12) / 2.0, (m02 - m20) / 2.0, (m10 - m01) / 2.0
        return math.atan2(math.sqrt(sx * sx + sy * sy + sz * sz), (trace - 1.0) / 2.0)
    if kind == 2:
        ax = R[0, 0] * tool_axis[0] + R[0, 1] * tool_axis[1] + R[0, 2] * tool_axis[2]
        ay = R[1, 0] * tool_axis[0] + R[1, 1] * tool_axis[1] + R[1, 2] * tool_axis[2]
        az = R[2, 0] * tool_axis[0] + R[2, 1] * tool_axis[1] + R[2, 2] * tool_axis[2]
        cx = ay * axis_ref[2] - az * axis_ref[1]
        cy = az * axis_ref[0] - ax * axis_ref[2]
        cz = ax * axis_ref[1] - ay * axis_ref[0]
        dot = ax * axis_ref[0] + ay * axis_ref[1] + az * axis_ref[2]
        return math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), dot)
    return 0.0
