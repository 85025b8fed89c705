"""Algorithm 1's inner loop compiled: iterations of BAORNN on a CompiledClearance.

The same steps as `Baornn.iterate` (Eqs. 1.15-1.24), with the objective (1.13) and the
projection (1.17) evaluated by `_evaluate`, so one control period is one call from Python.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from articula.numba_cache import jit
from articula.planning.newton_step import newton_from_chain, penalty_flat
from articula.planning.rate_limits import braking_path
from articula.planning.task import orientation_error
from articula.scene.compiled_clearance import _evaluate

# Ω's floor on self clearance [m] (docs/deviations.md, self-collision). The compiled GJK and
# coal's GJK/EPA agree to about 1e-6 m away from contact but not at it: a step the one finds
# 1 µm clear the other may find touching, so a planner that rides the boundary (d_min = 0)
# must stay clear by this margin. Here, not in objective.py, so that numba's cache of these
# kernels sees a change of it.
SELF_CONTACT_MARGIN = 1e-4


class Reference(NamedTuple):
    """A period's target as the kernels name it (Objective.reference packs it).

    Attributes:
        position: x_r, shape (3,) [m].
        task: the task's code (Task.code: 0 for a position task).
        weight: w of the orientation term [m/rad].
        tool_axis: the tool axis of an axis task, shape (3,) (end-effector frame).
        rotation: the reference rotation of a pose task, shape (3, 3).
        axis: the reference axis of an axis task, shape (3,) (world).
    """

    position: np.ndarray
    task: int
    weight: float
    tool_axis: np.ndarray
    rotation: np.ndarray
    axis: np.ndarray


class Problem(NamedTuple):
    """g's weights and Ω as the kernels name them (Objective.problem packs them).

    Attributes:
        lambda_weight: penalty weight Λ of Eq. (1.7) [m^(1+β)].
        beta: penalty exponent β of Eq. (1.7).
        d_min: hard clearance of Eq. (1.12) [m].
        self_d_min: hard clearance between the links of a checked pair [m].
        lower: lower bound of the projection box, shape (nq,) [rad].
        upper: upper bound of the projection box, shape (nq,) [rad].
        stop: the braking check (objective.Stop: q_base, change, sweep, last, jerk).
        clearance: the compiled scene with the pairs that count (ClearanceInputs, packed).
        static_min: smallest distance of the pairs that never move, per kind, shape (2,) [m].
    """

    lambda_weight: float
    beta: float
    d_min: float
    self_d_min: float
    lower: np.ndarray
    upper: np.ndarray
    stop: tuple
    clearance: tuple
    static_min: np.ndarray


@jit()
def outside_omega(d: float, d_self: float, d_min: float, self_d_min: float) -> bool:
    """Whether a point is outside Ω: not d > d_min (1.12), or its self clearance not above
    self_d_min, and never within SELF_CONTACT_MARGIN (clearances are 0 on overlap, so d_min = 0
    still rejects a point inside an obstacle).

    Args:
        d: the point's smallest link-obstacle clearance [m].
        d_self: its smallest clearance between link pairs that count [m].
        d_min: the hard clearance of Eq. (1.12) [m].
        self_d_min: the hard clearance between the links of a checked pair [m].

    Returns:
        True when the projection must keep the current point.
    """
    return d <= d_min or d_self <= max(self_d_min, SELF_CONTACT_MARGIN)


@jit(inline="always")
def _task_error(ee, ee_R, reference):
    """||x_r − f(θ)|| (Eq. 1.5), plus weight · orientation error for a pose or axis task."""
    x_ref = reference.position
    ex, ey, ez = x_ref[0] - ee[0], x_ref[1] - ee[1], x_ref[2] - ee[2]
    e = math.sqrt(ex * ex + ey * ey + ez * ez)
    if reference.task != 0:
        e += reference.weight * orientation_error(
            reference.task, reference.tool_axis, ee_R, reference.rotation, reference.axis
        )
    return e


@jit()
def stoppable(clipped, d, d_self, d_min, self_d_min, stop, clearance, static_min):
    """Whether the arm, at `clipped` after this period's motion from stop's q_base, stays in Ω
    while every joint then brakes as hard as its limits let it: at the end of every braking
    period (rate_limits.braking_path; the joints stop at different times, and the clearance
    between can be lower than at either end); a point is measured only where the clearance
    left since the last measured one could be used up on the way (a link pair's distance
    changes up to twice as fast as a link's to an obstacle).

    Args:
        clipped: the configuration at the end of the period, shape (nq,) [rad].
        d: its link-obstacle clearance [m].
        d_self: its clearance between checked link pairs [m].
        d_min: the hard clearance of Eq. (1.12) [m].
        self_d_min: the hard clearance between the links of a checked pair [m].
        stop: the braking check (objective.Stop: q_base, the period's start; change, each
            joint's largest change of motion per period, empty: no acceleration limit; sweep,
            how far a shape point moves at most per unit of each joint's motion; last, the
            motion before; jerk, the largest change of the change, empty: none).
        clearance: the compiled scene with the pairs that count (ClearanceInputs,
            packed).
        static_min: smallest distance of the pairs that never move, per kind, shape (2,) [m].

    Returns:
        True when braking from `clipped` stays clear (or there is no acceleration limit).
    """
    q_base, change, sweep, last, jerk = stop
    if change.size == 0:
        return True
    path = braking_path(clipped - q_base, last, change, jerk)
    room = min(d - d_min, 0.5 * (d_self - max(self_d_min, SELF_CONTACT_MARGIN)))
    before = clipped
    for k in range(path.shape[0]):
        q_k = clipped + path[k]
        for j in range(clipped.size):  # no point of the arm moves farther than this
            room -= sweep[j] * abs(q_k[j] - before[j])
        if room <= 0.0:  # the clearance left could be used up here: measure it
            d_k, d_self_k, _, _ = _evaluate(q_k, clearance, static_min)
            if outside_omega(d_k, d_self_k, d_min, self_d_min):
                return False
            room = min(d_k - d_min, 0.5 * (d_self_k - max(self_d_min, SELF_CONTACT_MARGIN)))
        before = q_k
    return True


@jit(inline="always")
def _braking_clear(q, d, d_self, problem):
    """stoppable with the problem's Ω and braking check."""
    p = problem
    return stoppable(q, d, d_self, p.d_min, p.self_d_min, p.stop, p.clearance, p.static_min)


@jit()
def _project_and_value(q, q_current, g_current, e_current, reference, problem):
    """(P_Ω(q), g there, the task error e there), Eqs. (1.17)-(1.18); stays at (q_current,
    g_current, e_current) when the clipped point is outside Ω (outside_omega) or, with
    acceleration limits, cannot brake inside it (stoppable). The pairs in the problem's
    clearance are the ones that count (an obstacle clearance of +inf: none)."""
    clipped = np.minimum(np.maximum(q, problem.lower), problem.upper)
    d, d_self, ee, ee_R = _evaluate(clipped, problem.clearance, problem.static_min)
    if outside_omega(d, d_self, problem.d_min, problem.self_d_min) or not _braking_clear(
        clipped, d, d_self, problem
    ):
        return q_current, g_current, e_current
    e = _task_error(ee, ee_R, reference)  # Eq. (1.5), with the orientation term
    return clipped, _penalised(e, d, problem.lambda_weight, problem.beta), e


@jit()
def _penalised(e, d, lambda_weight, beta):
    """g = e + Λ/d^β (Eq. 1.7), e alone without a penalty or an obstacle to count."""
    if lambda_weight > 0.0 and d < np.inf:
        return e + lambda_weight / d**beta if d > 0.0 else np.inf
    return e


@jit()
def iterations(q, g, reference, directions, c1, c2, problem):
    """Run one iteration of Algorithm 1 per row of `directions`; returns the accepted (q, g).

    Args:
        q: joint angles, shape (nq,) [rad].
        g: objective g(q) there.
        reference: the period's target (Reference, packed: Objective.reference).
        directions: raw Gaussian draws, one row per iteration, normalised here, shape (k, nq).
        c1: antenna length constant of Eq. (1.23) [rad/√m].
        c2: step constant of Eq. (1.24).
        problem: g's weights and Ω (Problem, packed: Objective.problem).

    Returns:
        The accepted joint angles, shape (nq,) [rad], and their objective g.
    """
    reference, problem = Reference(*reference), Problem(*problem)
    for k in range(directions.shape[0]):
        b = directions[k] / math.sqrt(directions[k] @ directions[k])
        lam = c1 * math.sqrt(g) if math.isfinite(g) else c1  # Eq. (1.23)
        _, g_left, _ = _project_and_value(q + lam * b, q, g, 0.0, reference, problem)
        _, g_right, _ = _project_and_value(q - lam * b, q, g, 0.0, reference, problem)
        diff = g_left - g_right
        sign = 1.0 if diff > 0.0 else (-1.0 if diff < 0.0 else 0.0)  # 0 when both are inf
        step = q - c2 * lam * sign * b  # Eqs. (1.19), (1.24)
        q_new, g_new, _ = _project_and_value(step, q, g, 0.0, reference, problem)
        if g_new < g:  # Eqs. (1.21)-(1.22)
            q, g = q_new, g_new
    return q, g


@jit()
def antenna_cap(lower: np.ndarray, upper: np.ndarray) -> float:
    """The longest antenna [rad] worth its evaluations in the box [lower, upper]: half its
    diagonal (a longer one is clipped back onto the box's faces, and its difference then
    says little about the gradient); inf for an unbounded box.

    Args:
        lower: lower bound of the projection box, shape (nq,) [rad].
        upper: upper bound of the projection box, shape (nq,) [rad].

    Returns:
        The largest antenna length [rad].
    """
    total = 0.0
    for j in range(lower.size):
        span = upper[j] - lower[j]
        total += span * span
    return 0.5 * math.sqrt(total)


@jit()
def antenna_scale(pair: int, short: float) -> float:
    """Length of antenna pair `pair` relative to λ_k: every second pair is short.

    Args:
        pair: index of the antenna pair (0 first).
        short: relative length of the short pairs.

    Returns:
        1 for an even pair, `short` for an odd one.
    """
    return 1.0 if pair % 2 == 0 else short


@jit()
def tracking_cap(e: float, g: float, d: float, yield_distance: float) -> float:
    """The largest task error [m] a baornn-improved period may accept: e, the error at its
    start, while the arm is at least yield_distance clear (the penalty then moves the arm
    only through the redundancy, never off the path); inf closer, or from a start outside Ω
    (g = inf), where g alone decides as in Eq. (1.21).

    Args:
        e: the task error at the period's start [m].
        g: the objective there (inf outside Ω).
        d: the start's smallest link-obstacle clearance [m].
        yield_distance: the clearance below which the task error may grow [m].

    Returns:
        The cap on an accepted point's task error [m].
    """
    return e if math.isfinite(g) and d >= yield_distance else math.inf


@jit()
def _orthonormal_columns(draw):
    """The columns of `draw` (n × m, m ≤ n) made orthonormal by Gram-Schmidt, as rows: the Q
    of its QR up to the signs of its columns (which only swap an antenna pair's ends)."""
    out = np.ascontiguousarray(draw.T)
    for j in range(out.shape[0]):
        for i in range(j):
            out[j] -= (out[i] @ out[j]) * out[i]
        out[j] /= math.sqrt(out[j] @ out[j])
    return out


@jit()
def improved_period(q, g_known, warm_motion, reference, draws, c1, c2, short, yield_distance,
                    damping, quiet_error, flat_slope, problem):  # fmt: skip
    """One control period of baornn-improved (planning/baornn_improved.py): g at q for the
    new reference (inf outside Ω; g_known instead when it is not NaN: a caller's g(q)), the
    warm start q + warm_motion (none when it is empty), the Gauss-Newton candidate
    (planning/newton_step.py; none when damping is 0), then one iteration per draws[k], an
    (n × pairs) Gaussian matrix whose orthonormalised columns are the antenna directions.
    While q is at least yield_distance clear, no accepted point has a larger task error than
    q has (tracking_cap). Where the penalty is flat there (penalty_flat), the Gauss-Newton
    candidate is tried and the iterations end once the accepted error is below quiet_error.

    Args:
        q: joint angles at the start of the period, shape (nq,) [rad].
        g_known: the caller's g(q), or NaN to compute it here.
        warm_motion: last period's joint motion, shape (nq,) [rad]; empty for no warm start.
        reference: the period's target (Reference, packed: Objective.reference).
        draws: Gaussian draws, one matrix per iteration, shape (k, nq, pairs).
        c1: antenna length constant, λ_k = c1·√e_k [rad/√m].
        c2: step constant of Eq. (1.24).
        short: relative length of every second antenna pair.
        yield_distance: the clearance below which the task error may grow [m].
        damping: μ of the Gauss-Newton candidate [m]; 0: no candidate.
        quiet_error: task error below which a period stops iterating [m].
        flat_slope: the penalty's slope below which it counts as flat [-].
        problem: g's weights and Ω (Problem, packed: Objective.problem).

    Returns:
        The accepted joint angles, shape (nq,) [rad], their objective g, the number of
        objective evaluations and the number of iterations run.
    """
    reference, problem = Reference(*reference), Problem(*problem)
    d, d_self, ee, ee_R = _evaluate(q, problem.clearance, problem.static_min)
    e = _task_error(ee, ee_R, reference)
    g = _penalised(e, d, problem.lambda_weight, problem.beta) if math.isnan(g_known) else g_known
    if math.isnan(g_known) and (
        outside_omega(d, d_self, problem.d_min, problem.self_d_min)
        or not _braking_clear(q, d, d_self, problem)
    ):
        g = math.inf  # a start outside Ω: any point inside it is better
    cap = tracking_cap(e, g, d, yield_distance)
    flat = penalty_flat(d, problem.lambda_weight, problem.beta, flat_slope)
    evaluations = 0
    if warm_motion.size:
        q_warm, g_warm, e_warm = _project_and_value(q + warm_motion, q, g, e, reference, problem)
        evaluations += 1
        if g_warm < g and e_warm <= cap:
            q, g, e = q_warm, g_warm, e_warm
    if flat and damping > 0.0:
        q_newton = newton_from_chain(q, reference, problem.clearance, damping, problem.lower,
                                     problem.upper)  # fmt: skip
        q_gn, g_gn, e_gn = _project_and_value(q_newton, q, g, e, reference, problem)
        evaluations += 1
        if g_gn < g and e_gn <= cap:
            q, g, e = q_gn, g_gn, e_gn
    n = q.size
    longest = antenna_cap(problem.lower, problem.upper)
    run = 0
    for k in range(draws.shape[0]):
        if flat and e < quiet_error:
            break  # on the path: the penalty has nothing to trade against (change 7)
        run += 1
        lam = min(c1 * math.sqrt(e), longest)  # c1·√e_k, e_k the task error at the accepted q
        directions = _orthonormal_columns(draws[k])
        gradient = np.zeros(n)
        best_q, best_g, best_e = q, g, e
        for j in range(directions.shape[0]):
            b = directions[j]
            scale = antenna_scale(j, short)
            q_left, g_left, e_left = _project_and_value(
                q + scale * lam * b, q, g, e, reference, problem
            )
            q_right, g_right, e_right = _project_and_value(
                q - scale * lam * b, q, g, e, reference, problem
            )
            evaluations += 2
            if math.isfinite(g_left) and math.isfinite(g_right):
                gradient += (g_left - g_right) / scale * b
            if g_left < best_g and e_left <= cap:
                best_q, best_g, best_e = q_left, g_left, e_left
            if g_right < best_g and e_right <= cap:
                best_q, best_g, best_e = q_right, g_right, e_right
        norm = math.sqrt(gradient @ gradient)
        if norm > 0.0:
            step = q - c2 * lam * gradient / norm  # Eq. (1.19) along the estimated gradient
            q_new, g_new, e_new = _project_and_value(step, q, g, e, reference, problem)
            evaluations += 1
            if g_new < best_g and e_new <= cap:  # Eqs. (1.21)-(1.22)
                best_q, best_g, best_e = q_new, g_new, e_new
        q, g, e = best_q, best_g, best_e
    return q, g, evaluations, run
