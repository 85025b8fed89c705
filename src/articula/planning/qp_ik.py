"""Reactive QP baseline after Haviland & Corke's NEO: velocity dampers on link-obstacle
distances and joint limits, a slack on the end-effector velocity, solved every period."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import qpsolvers

from articula.errors import ConfigError
from articula.planning.clearance import clearance_rows
from articula.planning.reference_velocity import reference_velocity
from articula.scene.scene import Scene


@dataclass(frozen=True)
class QpIkParams:
    """min ½ λ_q |q̇|² + ½ λ_δ |δ|² s.t. J q̇ + δ = ẋ_r + K e, dampers, speed bounds.

    gain K [1/s]; joint_weight λ_q and slack_weight λ_δ; damper gain ξ [m/s or rad/s];
    influence d_i and safety d_s distances [m] (ḋ ≥ −ξ (d − d_s)/(d_i − d_s) for d < d_i);
    limit_influence and limit_safety [rad] the same damper on the distance to each joint
    limit; speed_scale scales the URDF joint velocity limits.
    """

    gain: float = 20.0
    joint_weight: float = 0.01
    slack_weight: float = 100.0
    damper_gain: float = 1.0
    influence: float = 0.15
    safety: float = 0.03
    limit_influence: float = 0.2
    limit_safety: float = 0.02
    speed_scale: float = 1.0

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ConfigError(f"planner.{name}", f"must be finite and >= 0 (got {value})")
        if self.speed_scale <= 0:
            raise ConfigError("planner.speed_scale", "must be > 0 (a fraction of the URDF limits)")
        if self.safety >= self.influence or self.limit_safety >= self.limit_influence:
            raise ConfigError("planner.safety", "must be smaller than its influence distance")


@dataclass
class QpIk:
    """The NEO-style controller on the same Scene distances and Jacobians (daqp via qpsolvers)."""

    scene: Scene
    dt: float
    params: QpIkParams = field(default_factory=QpIkParams)
    d_min: float = 0.0
    iterations: int = field(default=0, init=False)
    infeasible: int = field(default=0, init=False)
    _previous_ref: np.ndarray | None = field(default=None, init=False)

    def step(self, q: np.ndarray, x_ref: np.ndarray, t: float) -> np.ndarray:
        """One period: solve for q̇ (stop if the QP has no solution) and integrate for dt."""
        qdot = self._solve(q, x_ref, t)
        self.iterations += 1
        if qdot is None:
            self.infeasible += 1
            return q.copy()
        return self.scene.robot.clip(q + self.dt * qdot)

    def _solve(self, q: np.ndarray, x_ref: np.ndarray, t: float) -> np.ndarray | None:
        robot, p, n = self.scene.robot, self.params, self.scene.robot.nq
        x = robot.ee_position(q)
        v = reference_velocity(x_ref, self._previous_ref, x, self.dt, p.gain)
        self._previous_ref = x_ref.copy()
        J = robot.jacobian(q)[:3]
        P = np.diag(np.r_[np.full(n, p.joint_weight), np.full(3, p.slack_weight)])
        A = np.hstack([J, np.eye(3)])
        G_rows, h_rows = [], []
        if self.scene.obstacles:
            rows = clearance_rows(self.scene, q, t, p.influence)
            for d, grad in zip(rows.distance, rows.gradient, strict=True):
                if not np.any(grad):
                    continue  # a world-fixed link: no joint changes d, so no row can help
                # −∇d·q̇ ≤ ξ (d − d_s)/(d_i − d_s): approach no faster than the damper allows.
                G_rows.append(np.r_[-grad, np.zeros(3)])
                h_rows.append(p.damper_gain * (d - p.safety) / (p.influence - p.safety))
        for j in range(n):
            for sign, room in ((1.0, robot.upper[j] - q[j]), (-1.0, q[j] - robot.lower[j])):
                if room < p.limit_influence:
                    row = np.zeros(n + 3)
                    row[j] = sign
                    G_rows.append(row)
                    span = p.limit_influence - p.limit_safety
                    h_rows.append(p.damper_gain * (room - p.limit_safety) / span)
        limit = p.speed_scale * np.where(robot.velocity_limit > 0, robot.velocity_limit, 1e3)
        bound = np.r_[limit, np.full(3, 1e3)]
        G = np.array(G_rows) if G_rows else None
        h = np.array(h_rows) if h_rows else None
        solution = qpsolvers.solve_qp(P, np.zeros(n + 3), G, h, A, v, -bound, bound, solver="daqp")
        return None if solution is None else solution[:n]
