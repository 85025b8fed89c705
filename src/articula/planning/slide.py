"""Sliding along a clearance boundary: the smallest correction of a step that brings every
near pair back above its floor, so the step keeps its motion along the boundary instead of
being halved to nothing (DESIGN.md, "Safe and still moving")."""

from __future__ import annotations

import daqp
import numpy as np

from articula.planning.clearance import ClearanceRows

# How far above its floor (d_min or self_d_min) a corrected step puts a pair [m]: enough that
# the next period's round-off and the compiled GJK's 1e-6 m tolerance cannot cross the floor.
SLIDE_MARGIN = 2e-4
# A damper's target distance sits this far above its floor [m], so that an arm it holds at its
# target is not refused by the step check for losing a little clearance to curvature.
DAMPER_MARGIN = 1e-3
# How much a joint correction of 1 rad weighs against 1 m of the task's motion [m²/rad²]: the
# correction moves the task as little as it can (through the redundancy) before it moves
# the joints at all.
JOINT_WEIGHT = 1e-4
# Rows within this much more than their target count in a correction, so that pushing one
# pair out does not push a neighbour in [m].
SLIDE_BAND = 1e-3


def slide_correction(
    rows: ClearanceRows,
    floors: tuple[float, float] | np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    task_jacobian: np.ndarray,
    residual: np.ndarray | None = None,
    weight: float = JOINT_WEIGHT,
    band: float = SLIDE_BAND,
) -> np.ndarray | None:
    """The joint correction Δ [rad] with ∇d_i·Δ ≥ floor_i + SLIDE_MARGIN − d_i for every row
    within `band` of that target, and low ≤ Δ ≤ high, that fits the task best,
    |JΔ − r|² + weight·|Δ|²: with r = 0 the step's projection back onto the feasible side, to
    first order, that moves the task least, keeping its motion along the boundary; with r the
    task's residual, a Gauss-Newton step toward the path that slides along the boundary.

    Args:
        rows: the clearance rows at the step's end (distances [m], gradients [m/rad], which
            rows are link pairs).
        floors: (d_min, self_d_min), the floors of link-obstacle and link-link rows [m].
        low: the lowest correction each joint may take (the period's box minus the step),
            shape (nq,) [rad].
        high: the highest, shape (nq,) [rad].
        task_jacobian: J of the task's rows, shape (m, nq) [m/rad, or weighted rad/rad].
        residual: r, the task motion wanted, shape (m,) [m]; None: none (zeros).
        weight: the cost of 1 rad of correction against 1 m of task misfit [m²/rad²].
        band: rows within this much of their target count [m].

    Returns:
        The correction, shape (nq,) [rad]; zeros when no row is near its floor and r is None;
        None when no correction within [low, high] meets the rows (to first order).
    """
    n = low.size
    floor = np.where(rows.self_pair, floors[1], floors[0]) + SLIDE_MARGIN
    near = rows.distance < floor + band
    if not np.any(near) and residual is None:
        return np.zeros(n)
    A = np.ascontiguousarray(rows.gradient[near])
    if np.any(np.all(A == 0.0, axis=1) & (rows.distance[near] < floor[near])):
        return None  # a row below its floor that no joint moves
    need = floor[near] - rows.distance[near]
    upper = np.concatenate([high, np.full(need.size, 1e30)])
    lower = np.concatenate([low, need])
    H = task_jacobian.T @ task_jacobian + weight * np.eye(n)
    f = np.zeros(n) if residual is None else -task_jacobian.T @ residual
    solution, _, status, _ = daqp.solve(H, f, A, upper, lower, np.zeros(upper.size, dtype=np.intc))
    if status <= 0:
        return None
    return np.clip(solution, low, high)
