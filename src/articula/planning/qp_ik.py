"""Reactive QP baseline after Haviland & Corke's NEO: velocity dampers on link-obstacle
distances (and checked link-link ones) and joint limits, a slack on each task row, solved
every period."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import daqp
import numpy as np
from pydantic import model_validator

from articula.numba_cache import jit
from articula.planning.clearance import RowSource
from articula.planning.reference_velocity import RateParams, task_rows
from articula.planning.task import Target, Task, as_target
from articula.scene.scene import Scene
from articula.validation import NonNegative, field_error


class QpIkParams(RateParams):
    """min ½ λ_q |q̇|² + ½ λ_δ |δ|² s.t. J q̇ + δ = ẋ_r + K e, dampers, speed bounds.

    Attributes:
        gain: K on the task error [1/s].
        influence: distance d_i below which an obstacle's damper acts [m].
        speed_scale: fraction of the URDF joint velocity limits.
        joint_weight: λ_q.
        slack_weight: λ_δ.
        damper_gain: ξ [m/s] (rad/s for joint limits).
        safety: d_s [m]; with influence d_i, ḋ ≥ −ξ (d − d_s)/(d_i − d_s) for d < d_i.
        self_safety: d_s for two links of the arm [m] (checked self-collision pairs): smaller,
            as some sit closer than `safety` by design.
        limit_influence: d_i of the same damper on the distance to each joint limit [rad].
        limit_safety: d_s of the joint-limit damper [rad].

    The slack weight and the joint-limit damper were made stiffer and narrower in issue 13
    (docs/deviations.md): the earlier 100 and 0.2 / 0.02 rad gave up millimetres of tracking
    near a joint limit that mink's plain limit keeps.
    """

    joint_weight: NonNegative = 0.01
    slack_weight: NonNegative = 1e4
    damper_gain: NonNegative = 1.0
    safety: NonNegative = 0.03
    self_safety: NonNegative = 0.005
    limit_influence: NonNegative = 0.05
    limit_safety: NonNegative = 0.005

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
    """The NEO-style controller on the same Scene distances and Jacobians, solved by daqp.

    Attributes:
        scene: the robot, its obstacles and its checked link pairs.
        dt: control period [s].
        params: weights, gains and damper distances of the QP.
        d_min: hard minimum clearance the start must respect (Eq. 1.12) [m].
        task: what the end effector tracks.
        use_compiled: take distances and kinematics from CompiledClearance where possible.
        iterations: QP solves so far.
        infeasible: periods whose QP had no solution (the arm stopped).
    """

    scene: Scene
    dt: float
    params: QpIkParams = field(default_factory=QpIkParams)
    d_min: float = 0.0
    task: Task = field(default_factory=Task)
    use_compiled: bool = True
    iterations: int = field(default=0, init=False)
    infeasible: int = field(default=0, init=False)
    _previous: Target | None = field(default=None, init=False)
    _rows: RowSource = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._rows = RowSource(self.scene, self.use_compiled)

    def reset(self) -> None:
        """Forget the previous target: the next period has no feed-forward."""
        self._previous = None

    def step(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray:
        """One period: solve for q̇ (stop if the QP has no solution) and integrate for dt.

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles after dt, clipped to the joint limits, shape (nq,) [rad].
        """
        qdot = self._solve(q, as_target(target), t)
        self.iterations += 1
        if qdot is None:
            self.infeasible += 1
            return q.copy()
        return self.scene.robot.clip(q + self.dt * qdot)

    def _solve(self, q: np.ndarray, target: Target, t: float) -> np.ndarray | None:
        robot, p, n = self.scene.robot, self.params, self.scene.robot.nq
        ee, rows = self._rows(q, t, p.influence)
        J, v = task_rows(ee.x, ee.R, ee.J, self.task, target, self._previous, self.dt, p.gain)
        self._previous = target
        model = robot.model
        H, A, upper, lower, sense = _qp_arrays(
            q, model.lowerPositionLimit, model.upperPositionLimit, self._speed_bound, J, v,
            rows.distance, rows.gradient, rows.self_pair, p.safety, p.self_safety, p.influence,
            p.damper_gain, p.limit_influence, p.limit_safety, p.joint_weight, p.slack_weight,
        )  # fmt: skip
        solution, _, status, _ = daqp.solve(H, np.zeros(H.shape[0]), A, upper, lower, sense)
        return solution[:n] if status > 0 else None

    @cached_property
    def _speed_bound(self) -> np.ndarray:
        """The joint speed bound [rad/s]: a URDF limit of 0 means none was given."""
        limit = self.scene.robot.velocity_limit
        return self.params.speed_scale * np.where(limit > 0, limit, 1e3)


@jit()
def _qp_arrays(
    q, q_lower, q_upper, speed_bound, J, v, distance, gradient, self_pair, safety, self_safety,
    influence, damper_gain, limit_influence, limit_safety, joint_weight, slack_weight,
):  # fmt: skip
    """daqp's (H, A, upper, lower, sense) of one period: box bounds on (q̇, δ), then the
    inequality rows G x ≤ h, then the task rows J q̇ + δ = v (sense 5, equality)."""
    n, m, c = q.size, J.shape[0], distance.size
    near_up = np.flatnonzero(q_upper - q < limit_influence)
    near_down = np.flatnonzero(q - q_lower < limit_influence)
    k = c + near_up.size + near_down.size  # inequality rows
    A = np.zeros((k + m, n + m))
    upper = np.empty(n + m + k + m)
    lower = np.full(upper.size, -1e30)
    upper[:n] = speed_bound
    upper[n : n + m] = 1e3
    # Velocity dampers: −∇d·q̇ ≤ ξ (d − d_s)/(d_i − d_s), approach no faster than that.
    for r in range(c):
        d_s = self_safety if self_pair[r] else safety
        A[r, :n] = -gradient[r]
        upper[n + m + r] = damper_gain * (distance[r] - d_s) / (influence - d_s)
    # Joint-limit dampers: the same law on the room left to each limit [rad].
    span = limit_influence - limit_safety
    for i, j in enumerate(near_up):
        A[c + i, j] = 1.0
        upper[n + m + c + i] = damper_gain * (q_upper[j] - q[j] - limit_safety) / span
    for i, j in enumerate(near_down):
        A[c + near_up.size + i, j] = -1.0
        upper[n + m + c + near_up.size + i] = (
            damper_gain * (q[j] - q_lower[j] - limit_safety) / span
        )
    A[k:, :n] = J
    for i in range(m):
        A[k + i, n + i] = 1.0
    upper[n + m + k :] = v
    lower[: n + m] = -upper[: n + m]
    sense = np.zeros(upper.size, dtype=np.intc)
    sense[n + m + k :] = 5
    H = np.zeros((n + m, n + m))
    for i in range(n + m):
        H[i, i] = joint_weight if i < n else slack_weight
    return H, A, upper, lower, sense
