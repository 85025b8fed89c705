"""Reactive QP baseline after Haviland & Corke's NEO: velocity dampers on link-obstacle
distances (and checked link-link ones) and joint limits, a slack on each task row, solved
every period."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import qpsolvers
from pydantic import model_validator

from articula.planning.clearance import clearance_rows
from articula.planning.reference_velocity import RateParams, task_rows
from articula.planning.task import Target, Task, as_target
from articula.scene.scene import Scene
from articula.validation import NonNegative, field_error


class QpIkParams(RateParams):
    """min ½ λ_q |q̇|² + ½ λ_δ |δ|² s.t. J q̇ + δ = ẋ_r + K e, dampers, speed bounds.

    Attributes (besides RateParams'):
        joint_weight: λ_q [-]; slack_weight: λ_δ [-].
        damper_gain: ξ [m/s] (rad/s for joint limits).
        safety: d_s [m]; with influence d_i, ḋ ≥ −ξ (d − d_s)/(d_i − d_s) for d < d_i.
        self_safety: d_s for two links of the arm [m] (checked self-collision pairs): smaller,
            as some sit closer than `safety` by design.
        limit_influence, limit_safety: the same damper on the distance to each joint limit [rad].
    """

    joint_weight: NonNegative = 0.01
    slack_weight: NonNegative = 100.0
    damper_gain: NonNegative = 1.0
    safety: NonNegative = 0.03
    self_safety: NonNegative = 0.005
    limit_influence: NonNegative = 0.2
    limit_safety: NonNegative = 0.02

    @model_validator(mode="after")
    def _safety_inside_influence(self) -> QpIkParams:
        for name in ("safety", "self_safety"):
            if getattr(self, name) >= self.influence:
                raise field_error(name, f"must be smaller than influence = {self.influence} m")
        if self.limit_safety >= self.limit_influence:
            raise field_error(
                "limit_safety", f"must be smaller than limit_influence = {self.limit_influence} rad"
            )
        return self


@dataclass
class QpIk:
    """The NEO-style controller on the same Scene distances and Jacobians (daqp via qpsolvers)."""

    scene: Scene
    dt: float
    params: QpIkParams = field(default_factory=QpIkParams)
    d_min: float = 0.0
    task: Task = field(default_factory=Task)
    iterations: int = field(default=0, init=False)
    infeasible: int = field(default=0, init=False)
    _previous: Target | None = field(default=None, init=False)

    def reset(self) -> None:
        """Forget the previous target: the next period has no feed-forward."""
        self._previous = None

    def step(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray:
        """One period: solve for q̇ (stop if the QP has no solution) and integrate for dt."""
        qdot = self._solve(q, as_target(target), t)
        self.iterations += 1
        if qdot is None:
            self.infeasible += 1
            return q.copy()
        return self.scene.robot.clip(q + self.dt * qdot)

    def _solve(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray | None:
        robot, p, n = self.scene.robot, self.params, self.scene.robot.nq
        J, v = task_rows(robot, q, self.task, target, self._previous, self.dt, p.gain)
        self._previous = target
        m = J.shape[0]  # task rows, each with its slack
        P = np.diag(np.r_[np.full(n, p.joint_weight), np.full(m, p.slack_weight)])
        A = np.hstack([J, np.eye(m)])
        G_rows, h_rows = [], []
        if self.scene.has_clearance:
            rows = clearance_rows(self.scene, q, t, p.influence)
            for d, grad, itself in zip(rows.distance, rows.gradient, rows.self_pair, strict=True):
                if not np.any(grad):
                    continue  # a world-fixed link: no joint changes d, so no row can help
                # −∇d·q̇ ≤ ξ (d − d_s)/(d_i − d_s): approach no faster than the damper allows.
                safety = p.self_safety if itself else p.safety
                G_rows.append(np.r_[-grad, np.zeros(m)])
                h_rows.append(p.damper_gain * (d - safety) / (p.influence - safety))
        for j in range(n):
            for sign, room in ((1.0, robot.upper[j] - q[j]), (-1.0, q[j] - robot.lower[j])):
                if room < p.limit_influence:
                    row = np.zeros(n + m)
                    row[j] = sign
                    G_rows.append(row)
                    span = p.limit_influence - p.limit_safety
                    h_rows.append(p.damper_gain * (room - p.limit_safety) / span)
        limit = p.speed_scale * np.where(robot.velocity_limit > 0, robot.velocity_limit, 1e3)
        bound = np.r_[limit, np.full(m, 1e3)]
        G = np.array(G_rows) if G_rows else None
        h = np.array(h_rows) if h_rows else None
        solution = qpsolvers.solve_qp(P, np.zeros(n + m), G, h, A, v, -bound, bound, solver="daqp")
        return None if solution is None else solution[:n]
