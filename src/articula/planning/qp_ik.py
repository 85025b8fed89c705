"""Reactive QP baseline after Haviland & Corke's NEO: velocity dampers on link-obstacle
distances (and checked link-link ones) and joint limits, a slack on each task row, solved
every period."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import daqp
import numpy as np
from pydantic import model_validator

from articula.numba_cache import jit
from articula.planning.reference_velocity import RateParams
from articula.planning.resolved_rate import ResolvedRate
from articula.planning.slide import DAMPER_MARGIN
from articula.planning.task import Target
from articula.validation import NonNegative, field_error

UNLIMITED = 1e3  # [rad/s] the solver's bound on a joint speed no limit bounds


class QpIkParams(RateParams):
    """min ½ λ_q |q̇|² + ½ λ_δ |δ|² s.t. J q̇ + δ = ẋ_r + K e, dampers, speed bounds.

    Attributes:
        gain: K on the task error [1/s].
        influence: distance d_i below which an obstacle's damper acts [m].
        speed_scale: fraction of the URDF joint velocity limits.
        joint_weight: λ_q.
        slack_weight: λ_δ.
        damper_gain: ξ [m/s] (rad/s for joint limits).
        safety: d_s [m]; with influence d_i, ḋ ≥ −ξ (d − d_s)/(d_i − d_s) for d < d_i; at
            least d_min + DAMPER_MARGIN (planning/slide.py), above the step check's floor.
        self_safety: d_s for two links of the arm [m] (checked self-collision pairs; at least
            self_d_min + DAMPER_MARGIN): smaller,
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
    self_safety: NonNegative = 0.01
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
class QpIk(ResolvedRate):
    """The NEO-style controller on the same Scene distances and Jacobians, solved by daqp.

    Its joint velocities stay in the box the rate limits allow this period (speeds, and
    accelerations relative to the last motion); a damper that box cannot honour is relaxed to
    the nearest it can (the period counts as infeasible), and a period whose QP has no solution
    brakes as hard as the limits allow.

    Attributes:
        scene: the robot, its obstacles and its checked link pairs.
        dt: control period [s].
        params: weights, gains and damper distances of the QP.
        d_min: hard minimum clearance the start must respect (Eq. 1.12) [m].
        task: what the end effector tracks.
        use_compiled: take distances and kinematics from CompiledClearance where possible.
        rate: joint speed and acceleration limits; None: the URDF's speeds times
            params.speed_scale.
        iterations: QP solves so far.
        infeasible: periods whose QP had no solution (the arm braked), or where a damper or a
            limit could not hold.
    """

    dt: float
    params: QpIkParams = field(default_factory=QpIkParams)

    def step(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray:
        """One period: solve for q̇ within this period's box (brake if the QP has no
        solution) and integrate for dt.

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles after dt, within the joint limits, shape (nq,) [rad].
        """
        robot, p, n = self.scene.robot, self.params, self.scene.robot.nq
        box, rows, J, v = self._begin(q, target, t)
        # A joint without a speed limit still gets a finite bound for the solver [rad/s].
        qdot_low, qdot_high = (np.clip((b - q) / self.dt, -UNLIMITED, UNLIMITED) for b in box)
        model = robot.model
        change = self._limits.change
        H, A, upper, lower, sense, relaxed = _qp_arrays(
            q,
            model.lowerPositionLimit,
            model.upperPositionLimit,
            qdot_low,
            qdot_high,
            np.full(n, np.inf) if change is None else change,
            self.dt,
            J,
            v,
            rows.distance,
            rows.gradient,
            rows.self_pair,
            max(p.safety, self.d_min + DAMPER_MARGIN),
            max(p.self_safety, self.scene.self_d_min + DAMPER_MARGIN),
            p.influence,
            p.damper_gain,
            p.limit_influence,
            p.limit_safety,
            p.joint_weight,
            p.slack_weight,
        )
        solution, _, status, _ = daqp.solve(H, np.zeros(H.shape[0]), A, upper, lower, sense)
        if status <= 0:
            # Dampers that each can be met but not all at once (a start inside their safety
            # distance, the box of an arm at rest too small to push out along every row):
            # ask of each only that it does not approach, which rest meets.
            dampers = slice(H.shape[0], H.shape[0] + A.shape[0] - J.shape[0])
            upper[dampers] = np.maximum(upper[dampers], 0.0)
            relaxed = True
            solution, _, status, _ = daqp.solve(H, np.zeros(H.shape[0]), A, upper, lower, sense)
        self.iterations += 1
        if status <= 0:
            return self._finish(q, q, box, rows, t, strained=True)  # brake: nearest to rest
        return self._finish(q, q + self.dt * solution[:n], box, rows, t, strained=relaxed)


@jit()
def _qp_arrays(
    q,
    q_lower,
    q_upper,
    qdot_low,
    qdot_high,
    change,
    dt,
    J,
    v,
    distance,
    gradient,
    self_pair,
    safety,
    self_safety,
    influence,
    damper_gain,
    limit_influence,
    limit_safety,
    joint_weight,
    slack_weight,
):
    """daqp's (H, A, upper, lower, sense) of one period, and whether a damper was relaxed: box
    bounds on (q̇, δ) (q̇ within [qdot_low, qdot_high]), then the inequality rows G x ≤ h, then
    the task rows J q̇ + δ = v (sense 5, equality).

    With acceleration limits (`change`, each joint's largest change of motion per period
    [rad]; inf: none) a distance row also approaches no faster than it can still stop before
    d_s: a row's approach per period can shrink by C = Σ|∇d_j| c_j a period, so it keeps
    s + s²/(2C) ≤ d − d_s, as each joint does before its position limit. A damper row that no
    q̇ of the box meets is relaxed to the least any does (braking that cannot honour it is the
    most the arm can do)."""
    n, m, c = q.size, J.shape[0], distance.size
    near_up = np.flatnonzero(q_upper - q < limit_influence)
    near_down = np.flatnonzero(q - q_lower < limit_influence)
    k = c + near_up.size + near_down.size  # inequality rows
    A = np.zeros((k + m, n + m))
    upper = np.empty(n + m + k + m)
    lower = np.full(upper.size, -1e30)
    upper[:n] = qdot_high
    lower[:n] = qdot_low
    upper[n : n + m] = 1e3
    lower[n : n + m] = -1e3
    # Velocity dampers: −∇d·q̇ ≤ ξ (d − d_s)/(d_i − d_s), approach no faster than that.
    for r in range(c):
        d_s = self_safety if self_pair[r] else safety
        A[r, :n] = -gradient[r]
        upper[n + m + r] = damper_gain * (distance[r] - d_s) / (influence - d_s)
        brake = 0.0  # C of the row [m]
        for j in range(n):
            brake += abs(gradient[r, j]) * change[j]
        if 0.0 < brake < np.inf:
            room = max(distance[r] - d_s, 0.0)
            reach = brake * (math.sqrt(1.0 + 2.0 * room / brake) - 1.0)  # [m] per period
            upper[n + m + r] = min(upper[n + m + r], reach / dt)
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
    relaxed = False
    for r in range(k):
        least = 0.0  # the smallest A[r] q̇ over the box
        for j in range(n):
            least += min(A[r, j] * qdot_low[j], A[r, j] * qdot_high[j])
        if upper[n + m + r] < least:
            upper[n + m + r] = least + 1e-12 * (1.0 + abs(least))
            relaxed = True
    A[k:, :n] = J
    for i in range(m):
        A[k + i, n + i] = 1.0
    upper[n + m + k :] = v
    sense = np.zeros(upper.size, dtype=np.intc)
    sense[n + m + k :] = 5
    H = np.zeros((n + m, n + m))
    for i in range(n + m):
        H[i, i] = joint_weight if i < n else slack_weight
    return H, A, upper, lower, sense, relaxed
