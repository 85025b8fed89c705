"""Velocity-level baselines: Jacobian pseudo-inverse (JMPI) and damped least squares, with
obstacle avoidance through a repulsion term projected into the null space of the task."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from articula.planning.clearance import ClearanceRows
from articula.planning.rate_limits import ROUND_OFF
from articula.planning.reference_velocity import RateParams
from articula.planning.resolved_rate import ResolvedRate
from articula.planning.task import Target
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
class VelocityIk(ResolvedRate):
    """Resolved-rate control of the end effector's task (position, pose or axis).

    The period's joint motion is scaled into the box the rate limits allow (its change from
    the last motion keeps its direction), and a motion that would bring links closer than
    d_min to an obstacle or self_d_min to each other is halved toward braking.

    Attributes:
        scene: the robot, its obstacles and its checked link pairs.
        method: "pinv" (Jacobian pseudo-inverse) or "dls" (damped least squares).
        dt: control period [s].
        params: gains of the control law.
        d_min: hard minimum clearance (Eq. 1.12) the start and every step keep [m].
        task: what the end effector tracks.
        use_compiled: take distances and kinematics from CompiledClearance where possible.
        rate: joint speed and acceleration limits; None: the URDF's speeds times
            params.speed_scale.
        iterations: control periods computed so far.
        infeasible: periods that braked because no motion kept the clearances, or whose
            limits could not all hold.
    """

    method: Literal["pinv", "dls"]
    dt: float
    params: VelocityIkParams = field(default_factory=VelocityIkParams)

    def step(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray:
        """One period: integrate q̇ for dt within the period's box.

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles after dt, within the joint limits, shape (nq,) [rad].
        """
        robot, p = self.scene.robot, self.params
        box, rows, J, v = self._begin(q, target, t)
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
        motion = _scale_into(
            self.dt * _limit_speed(qdot, limit), box[0] - q, box[1] - q, self._limits.last_motion
        )
        return self._finish(q, q + motion, box, rows, t)

    def _repulsion(self, rows: ClearanceRows) -> np.ndarray:
        """The null-space term q̇_0 [rad/s] of the rows within the influence distance."""
        p = self.params
        if rows.distance.size == 0 or p.repulsion == 0:
            return np.zeros(self.scene.robot.nq)
        d = np.maximum(rows.distance, 1e-3)  # inside an obstacle: push as hard as at 1 mm
        weights = p.repulsion * (1.0 / d - 1.0 / p.influence) / d**2
        return weights @ rows.gradient


def _scale_into(
    motion: np.ndarray, low: np.ndarray, high: np.ndarray, last: np.ndarray | None
) -> np.ndarray:
    """The motion [rad] within [low, high]: its change from the last motion (clipped into the
    box; rest when there is none) scaled down uniformly until it fits; a joint over by no more
    than round-off is clipped instead (it would otherwise pin the scale at 0)."""
    base = np.clip(np.zeros_like(motion) if last is None else last, low, high)
    change = motion - base
    excess = np.maximum(motion - high, low - motion)
    over = excess > ROUND_OFF * np.maximum(high - low, 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        room = np.where(change > 0, (high - base) / change, (low - base) / change)
    scale = float(np.min(room[over], initial=1.0))
    return np.clip(base + min(1.0, max(scale, 0.0)) * change, low, high)


def _limit_speed(qdot: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """q̇ scaled down uniformly (direction kept) so that no joint exceeds its limit [rad/s];
    a URDF limit of 0 means none was given."""
    ratio = np.max(np.abs(qdot) / np.where(limit > 0, limit, np.inf))
    return qdot / ratio if ratio > 1.0 else qdot
