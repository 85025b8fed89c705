"""Smooth commands: the searches' period end re-chosen to use as little of the acceleration
limits as the task allows (beyond the book; docs/deviations.md, issue 43).

BAORNN's antennae are far longer than one period's change of motion (a·dt²), so the accepted
point lands on a face of the period's box: the faithful search commanded ≥ 0.9 of the
acceleration limit in 84-88 % of its settled periods, its sign reversing at ~20 Hz, and the
redundancy's motion is the noise of a random search. Here the period ends instead at the
change of motion Δ (from coasting: the start plus the last period's motion) that
- meets the task from the search's point to first order (the search's point is where the
  task and the clearance rows are linearised);
- keeps every near pair above its floor to first order, stays in the period's box, and asks
  for joint torques within TORQUE_SHARE of the efforts (torque_rows, where the URDF states
  inertias);
- moves the redundancy down the gradient of g's penalty (Eqs. 1.11, 1.14), its velocity
  damped by DAMPING per period: a smooth, deterministic descent of the penalty the search
  descends by random antennae; beyond g, the redundancy alone (the task's null space) also
  moves the joints off their limits and link pairs off self_d_min (keep_off_gradient):
  without it the arm drifted into a posture with a joint at its limit and a link pair at
  self_d_min, and stayed there while the path moved away (the book's circle, iiwa14,
  baornn-improved: up to 29 mm RMS);
- within those, uses the least of each joint's acceleration limit.
The result is projected onto Ω with the braking check like any candidate, and the search's
own point is kept when it is refused.
"""

from __future__ import annotations

import daqp
import numpy as np
import pinocchio as pin

from articula.planning.clearance import ClearanceRows
from articula.planning.slide import SLIDE_MARGIN

# The acceleration cost's scale [m]: a full change of motion on one joint costs half this of
# g; the penalty's slope times the joints' largest changes, over this, is the redundancy's
# push per period [-].
ACCELERATION_COST = 3e-5
# g's tracking term |e| (Eq. 1.11) is weighed as |e_new|² / (2 max(|e|, ERROR_FLOOR)): equal
# to |e| and of slope 1 where the search's point is, so that error is traded for clearance as
# g trades it; on the path, of slope |e| / ERROR_FLOOR [m].
ERROR_FLOOR = 1e-5
# The damping of the redundancy's velocity (the motion the task does not see) [-]: unpushed,
# a period keeps 1 / (1 + DAMPING) of it.
DAMPING = 0.2
# Rows within this much of their floor constrain the change [m] (the period's box moves a link
# by a few mm at most).
SMOOTH_BAND = 0.02
# Obstacle rows within this distance push the redundancy [m]; beyond it Λ/d changes little.
PENALTY_REACH = 0.25
# The penalty's nearest distance (Eq. 1.14) as a soft minimum of this width over the rows [m],
# so that two obstacles at nearly the same distance do not switch the push every period.
SOFT_MIN = 0.005
# The share of each joint's effort limit a smoothed change may ask for in rigid-body torque
# (gravity included) [-]: the rest is the arm's servo's, to correct its errors with.
TORQUE_SHARE = 0.7
# A joint within LIMIT_REACH of a limit [rad] is pushed off it as a link is from an obstacle
# LIMIT_LEVER times as far [m/rad] (a link about this far from the joint's axis).
LIMIT_REACH = 0.5
LIMIT_LEVER = 0.1
# Link pairs within SELF_REACH of self_d_min [m] are kept off it too, where the joints move
# them apart at least PAIR_STEER [m/rad]: a pair at a nearly constant distance (the UR10's
# wrist links) has a gradient that is its nearest points' noise, its sign flipping from one
# period to the next (±0.004 m/rad), which drove 43 % of the UR10's periods to the limits.
SELF_REACH = 0.02
PAIR_STEER = 0.02
# The keep-off asks at most this share of a joint's acceleration limit [-]: near a limit its
# slope is unbounded, and a redundancy driven at the limits leaves the path (to second order).
# (g's own push is not capped: the clearance it keeps fell to 2.1 mm of d_min = 2 mm.)
KEEP_OFF_SHARE = 0.5


def penalty_gradient(rows: ClearanceRows, lambda_weight: float, beta: float) -> np.ndarray:
    """∂/∂q of g's penalty Λ / d^β, d the nearest link-obstacle distance (Eqs. 1.11, 1.14),
    the nearest row's gradient replaced by a soft minimum (SOFT_MIN) over the rows.

    Args:
        rows: the clearance rows at q (link-link rows are not penalised).
        lambda_weight: Λ [m^(1+β)].
        beta: β.

    Returns:
        The gradient, shape (nq,) [m/rad]; zeros without Λ or obstacle rows.
    """
    obstacle = ~rows.self_pair & (rows.distance > 0)
    if lambda_weight == 0 or not np.any(obstacle):
        return np.zeros(rows.gradient.shape[1])
    d, gradient = rows.distance[obstacle], rows.gradient[obstacle]
    near = d.min()
    w = np.exp(-(d - near) / SOFT_MIN)
    return -lambda_weight * beta / near ** (beta + 1) * (w @ gradient) / w.sum()


def keep_off_gradient(
    q: np.ndarray,
    limits: tuple[np.ndarray, np.ndarray],
    rows: ClearanceRows,
    self_d_min: float,
    lambda_weight: float,
    beta: float,
) -> np.ndarray:
    """Beyond the book: the gradient of Σ Λ/(s_i + SLIDE_MARGIN)^β over the joints within
    LIMIT_REACH of a limit (s_i = LIMIT_LEVER times the joint's distance to it) and the link
    pairs within SELF_REACH of self_d_min that the joints move apart at least PAIR_STEER fast
    (s_i = the pair's distance above the floor), each less its slope at the reach so that it
    grows from 0: what keeps the redundancy off the floors g does not see.

    Args:
        q: the joint angles, shape (nq,) [rad].
        limits: the joints' lower and upper position limits, each shape (nq,) [rad] (±inf:
            none, as for a continuous joint).
        rows: the clearance rows at q (its link pairs are used).
        self_d_min: the link pairs' floor [m].
        lambda_weight: Λ [m^(1+β)]; 0: none, as g's penalty.
        beta: β.

    Returns:
        The gradient, shape (nq,) [m/rad].
    """
    room = np.minimum(q - limits[0], limits[1] - q)
    away = np.where(q - limits[0] < limits[1] - q, 1.0, -1.0)  # off the nearer limit
    slope = _barrier_slope(LIMIT_LEVER * room, LIMIT_LEVER * LIMIT_REACH, lambda_weight, beta)
    steered = np.linalg.norm(rows.gradient, axis=1) >= PAIR_STEER
    pairs = rows.self_pair & steered & (rows.distance < self_d_min + SELF_REACH)
    pair_slope = _barrier_slope(rows.distance[pairs] - self_d_min, SELF_REACH, lambda_weight, beta)
    return -LIMIT_LEVER * slope * away - pair_slope @ rows.gradient[pairs]


def _barrier_slope(s: np.ndarray, reach: float, lambda_weight: float, beta: float) -> np.ndarray:
    """d/ds of −Λ/(s + SLIDE_MARGIN)^β less its value at `reach`, 0 beyond it [-]."""

    def slope(x: np.ndarray | float) -> np.ndarray:
        return lambda_weight * beta / (np.maximum(x, 0.0) + SLIDE_MARGIN) ** (beta + 1)

    return np.where(s < reach, slope(s) - slope(reach), 0.0)


def torques_known(model: pin.Model) -> bool:
    """Whether the URDF states what torque_rows needs: inertias and an effort limit.

    Args:
        model: the arm's Pinocchio model.

    Returns:
        True where some link has mass and some joint a finite effort limit.
    """
    effort = np.asarray(model.effortLimit, dtype=float)
    return sum(inertia.mass for inertia in model.inertias) > 0 and bool(np.any(np.isfinite(effort)))


def torque_rows(
    model: pin.Model, data: pin.Data, q: np.ndarray, velocity: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The joint torques a period's change of motion Δ asks for, τ = M(q)·Δ/dt² + h(q, q̇)
    (the URDF's inertias; Pinocchio's CRBA and RNEA), as rows kept within ±TORQUE_SHARE of
    the effort limits (beyond the book: a change within the acceleration limits of the
    datasheet may still need more torque than the arm has).

    Args:
        model: the arm's Pinocchio model (its inertias and effort limits).
        data: a Pinocchio data of it, used as scratch.
        q: the joint angles at the period's end, shape (nq,) [rad].
        velocity: the joint velocities there, shape (nq,) [rad/s].
        dt: the control period [s].

    Returns:
        (A [N·m/rad], low, high [N·m]) with low ≤ A·Δ ≤ high (a joint without an effort limit
        kept within ±1e30). Meaningful only where torques_known(model).
    """
    effort = TORQUE_SHARE * np.asarray(model.effortLimit, dtype=float)
    inertia = pin.crba(model, data, q)
    inertia = np.triu(inertia) + np.triu(inertia, 1).T  # CRBA fills the upper triangle
    bias = pin.rnea(model, data, q, velocity, np.zeros_like(q))
    effort = np.where(np.isfinite(effort), effort, 1e30)
    return inertia / dt**2, -effort - bias, effort - bias


def smooth_change(
    searched: np.ndarray,
    coasting: np.ndarray,
    scale: np.ndarray,
    task_jacobian: np.ndarray,
    residual: np.ndarray,
    rows: ClearanceRows,
    floors: tuple[float, float],
    low: np.ndarray,
    high: np.ndarray,
    push: np.ndarray,
    error_cap: float = np.inf,
    keep_off: np.ndarray | None = None,
    torque: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> np.ndarray | None:
    """The period's change of motion Δ [rad] from coasting that descends g to first order from
    the search's point q_s with the least acceleration: with u = Δ/c, Δ' = Δ − Δ_s, it
    minimises |r − JΔ'|² / (2 min(max(|r + JΔ_s|, ERROR_FLOOR), error_cap)) + ∇P·Δ' + K·Δ_N
    + ACCELERATION_COST·(½Σu_i² + ½·DAMPING·|N(m/c + u)|²), N the projection onto the task's
    null space (in u), Δ_N = c·N(u − u_s) the change's part there, subject to
    ∇d_i·Δ' ≥ floor_i + SLIDE_MARGIN − d_i for every row within SMOOTH_BAND of its floor and
    low ≤ Δ ≤ high.

    Args:
        searched: the search's change of motion Δ_s (its point minus coasting), shape (nq,)
            [rad].
        coasting: the last period's motion m, shape (nq,) [rad].
        scale: each joint's largest change of motion per period, c = a·dt², shape (nq,) [rad].
        task_jacobian: J of the task's rows at q_s, shape (m, nq) [m/rad].
        residual: r, the task's residual there, shape (m,) [m].
        rows: the clearance rows at q_s.
        floors: (d_min, self_d_min) [m].
        low: the smallest change each joint may take (the period's box minus coasting),
            shape (nq,) [rad].
        high: the largest, shape (nq,) [rad].
        push: ∇P, the penalty's gradient at q_s (penalty_gradient), shape (nq,) [m/rad].
        error_cap: the error beyond which the tracking term stiffens, its slope |e| /
            error_cap > 1: how far off the path the penalty may trade the task for clearance
            (inf: as far as g trades it) [m].
        keep_off: a gradient descended through the task's null space only (linear, as ∇P)
            (keep_off_gradient), shape (nq,) [m/rad]; None: none.
        torque: rows (A, low, high) kept as low ≤ A·Δ ≤ high (torque_rows) [N·m]; None:
            none.

    Returns:
        Δ, shape (nq,) [rad]; None when no change within [low, high] keeps the rows (to first
        order).
    """
    n = scale.size
    M = task_jacobian * scale  # the task's rows per unit of each joint's limit
    wanted = residual + task_jacobian @ searched
    # The error where coasting ends, to first order: the search's own error is its noise.
    fit = ACCELERATION_COST * min(max(float(np.linalg.norm(wanted)), ERROR_FLOOR), error_cap)
    free = np.eye(n) - np.linalg.pinv(M) @ M  # the redundancy, in u
    damp = DAMPING * free.T @ free
    H = M.T @ M / fit + np.eye(n) + damp
    f = -M.T @ wanted / fit + push * scale / ACCELERATION_COST + damp @ (coasting / scale)
    if keep_off is not None:  # through the redundancy only: never traded for the task
        nudge = free @ (keep_off * scale) / ACCELERATION_COST
        f += nudge * min(1.0, KEEP_OFF_SHARE / max(float(np.abs(nudge).max()), 1e-300))
    floor = np.where(rows.self_pair, floors[1], floors[0]) + SLIDE_MARGIN
    near = rows.distance < floor + SMOOTH_BAND
    G = rows.gradient[near]
    need = floor[near] - rows.distance[near] + G @ searched
    A = G * scale
    upper = np.concatenate([high / scale, np.full(need.size, 1e30)])
    lower = np.concatenate([low / scale, need])
    if torque is not None:
        A = np.vstack([A, torque[0] * scale])
        lower, upper = np.concatenate([lower, torque[1]]), np.concatenate([upper, torque[2]])
    A = np.ascontiguousarray(A)
    sense = np.zeros(upper.size, dtype=np.intc)
    u, _, status, _ = daqp.solve(H, f, A, upper, lower, sense)
    if status <= 0:
        return None
    return np.clip(u * scale, low, high)
