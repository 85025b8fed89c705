"""Reactive QP baseline after Haviland & Corke's NEO: velocity dampers on link-obstacle
distances (and checked link-link ones) and joint limits, a slack on each task row, solved
every period."""

from __future__ import annotations

from dataclasses import dataclass, field

import daqp
import numpy as np
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
        dampers, h = self._clearance_dampers(q, t)
        # Joint-limit dampers: the same law on the room left to each limit [rad].
        up = robot.model.upperPositionLimit - q
        down = q - robot.model.lowerPositionLimit
        near_up = np.flatnonzero(up < p.limit_influence)
        near_down = np.flatnonzero(down < p.limit_influence)
        span = p.limit_influence - p.limit_safety
        rooms = np.r_[up[near_up], down[near_down]]
        k = len(dampers) + rooms.size  # inequality rows
        # daqp's layout: box bounds on (q̇, δ), then G x ≤ h, then J q̇ + δ = v (sense 5).
        rows = np.zeros((k + m, n + m))
        rows[: len(dampers), :n] = dampers
        limit_rows = rows[len(dampers) : k]
        limit_rows[np.arange(near_up.size), near_up] = 1.0
        limit_rows[near_up.size + np.arange(near_down.size), near_down] = -1.0
        rows[k:, :n] = J
        rows[k:, n:] = np.eye(m)
        limit = p.speed_scale * np.where(robot.velocity_limit > 0, robot.velocity_limit, 1e3)
        bound = np.r_[limit, np.full(m, 1e3)]
        upper = np.r_[bound, h, p.damper_gain * (rooms - p.limit_safety) / span, v]
        lower = np.full(upper.size, -1e30)
        lower[: n + m] = -bound
        sense = np.zeros(upper.size, dtype=np.intc)
        sense[n + m + k :] = 5  # equality rows
        weights = np.r_[np.full(n, p.joint_weight), np.full(m, p.slack_weight)]
        solution, _, status, _ = daqp.solve(np.diag(weights), np.zeros(n + m), rows, upper,
                                            lower, sense)  # fmt: skip
        return solution[:n] if status > 0 else None

    def _clearance_dampers(self, q: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(−∇d rows, their bounds) of the velocity dampers on every distance within the
        influence distance: −∇d·q̇ ≤ ξ (d − d_s)/(d_i − d_s), approach no faster than that."""
        p, n = self.params, self.scene.robot.nq
        if not self.scene.has_clearance:
            return np.zeros((0, n)), np.zeros(0)
        rows = clearance_rows(self.scene, q, t, p.influence)
        # A world-fixed link: no joint changes its d, so no row can help.
        moving = np.any(rows.gradient != 0.0, axis=1)
        safety = np.where(rows.self_pair[moving], p.self_safety, p.safety)
        h = p.damper_gain * (rows.distance[moving] - safety) / (p.influence - safety)
        return -rows.gradient[moving], h
