"""Velocity-level baselines: Jacobian pseudo-inverse (JMPI) and damped least squares, with
obstacle avoidance through a repulsion term projected into the null space of the task."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from articula.planning.clearance import ClearanceRows, RowSource
from articula.planning.reference_velocity import RateParams, task_rows
from articula.planning.task import Target, Task, as_target
from articula.scene.scene import Scene
from articula.validation import NonNegative

PINV_CUTOFF = 1e-6


class VelocityIkParams(RateParams):
    """Gains of q̇ = J#(ẋ_r + K e) + (I − J⁺J) q̇_0.

    Attributes:
        gain: K on the task error [1/s].
        influence: distance d_i beyond which nothing repels [m].
        speed_scale: fraction of the URDF joint velocity limits.
        damping: μ of DLS, J# = Jᵀ(JJᵀ + μ²I)⁻¹ [m].
        repulsion: η of the null-space term q̇_0 = η Σ (1/d − 1/d_i)/d² ∇d, the gradient of
            the classic FIRAS potential [m²/s].
    """

    damping: NonNegative = 0.02
    repulsion: NonNegative = 0.02


@dataclass
class VelocityIk:
    """Resolved-rate control of the end effector's task (position, pose or axis).

    Attributes:
        scene: the robot, its obstacles and its checked link pairs.
        method: "pinv" (Jacobian pseudo-inverse) or "dls" (damped least squares).
        dt: control period [s].
        params: gains of the control law.
        d_min: hard minimum clearance the start must respect (Eq. 1.12) [m].
        task: what the end effector tracks.
        use_compiled: take distances and kinematics from CompiledClearance where possible.
        iterations: control periods computed so far.
    """

    scene: Scene
    method: Literal["pinv", "dls"]
    dt: float
    params: VelocityIkParams = field(default_factory=VelocityIkParams)
    d_min: float = 0.0
    task: Task = field(default_factory=Task)
    use_compiled: bool = True
    iterations: int = field(default=0, init=False)
    _previous: Target | None = field(default=None, init=False)
    _rows: RowSource = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._rows = RowSource(self.scene, self.use_compiled)

    def reset(self) -> None:
        """Forget the previous target: the next period has no feed-forward."""
        self._previous = None

    def step(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray:
        """One period: integrate q̇ for dt and clip to the joint limits.

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles after dt, shape (nq,) [rad].
        """
        robot, p = self.scene.robot, self.params
        target = as_target(target)
        ee, rows = self._rows(q, t, p.influence)
        J, v = task_rows(ee.x, ee.R, ee.J, self.task, target, self._previous, self.dt, p.gain)
        self._previous = target
        m = J.shape[0]
        # Singular values below 1e-6 of the largest are round-off (the stretched home pose has
        # 1e-13): inverting them would let the last bits of q choose the direction of motion.
        J_pinv = np.linalg.pinv(J, rcond=PINV_CUTOFF)
        if self.method == "dls":
            J_task = J.T @ np.linalg.solve(J @ J.T + p.damping**2 * np.eye(m), np.eye(m))
        else:
            J_task = J_pinv
        limit = p.speed_scale * robot.velocity_limit
        # The repulsion grows like 1/d³: capped at half the joint speeds on its own, so that it
        # cannot, through the uniform scaling below, stall the task it is projected around.
        repulsion = _limit_speed(self._repulsion(rows), 0.5 * limit)
        qdot = J_task @ v + (np.eye(robot.nq) - J_pinv @ J) @ repulsion
        self.iterations += 1
        return robot.clip(q + self.dt * _limit_speed(qdot, limit))

    def _repulsion(self, rows: ClearanceRows) -> np.ndarray:
        """The null-space term q̇_0 [rad/s] of the rows within the influence distance."""
        p = self.params
        if rows.distance.size == 0 or p.repulsion == 0:
            return np.zeros(self.scene.robot.nq)
        d = np.maximum(rows.distance, 1e-3)  # inside an obstacle: push as hard as at 1 mm
        weights = p.repulsion * (1.0 / d - 1.0 / p.influence) / d**2
        return weights @ rows.gradient


def _limit_speed(qdot: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """q̇ scaled down uniformly (direction kept) so that no joint exceeds its limit [rad/s];
    a URDF limit of 0 means none was given."""
    ratio = np.max(np.abs(qdot) / np.where(limit > 0, limit, np.inf))
    return qdot / ratio if ratio > 1.0 else qdot
