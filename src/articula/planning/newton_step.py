"""Change 6 of baornn-improved: a damped Gauss-Newton candidate toward the period's target.

Beetle antennae estimate the gradient of g from random directions; near the path the task
term's own Jacobian gives the step to it directly. Each period tries, after the warm start,
q + Δq with Δq = Aᵀ(AAᵀ + μ²I)⁻¹ r (damped least squares on the task residual r and its
Jacobian A), solved again for the other joints where one would leave the period's box (a
joint of the box held at its bound: a box-bounded least squares); like every candidate
it is projected onto Ω (1.17) and kept only if it lowers g (1.21) within the tracking cap.
The same code serves the compiled period (planning/baornn_kernel.py, its Jacobian from the
compiled chain) and the Python reference loop (Pinocchio's).
"""

from __future__ import annotations

import math

import numpy as np

from articula.numba_cache import jit
from articula.scene.compiled_bundles import named_inputs
from articula.scene.compiled_poses import _ee_pose, _joint_poses
from articula.scene.compiled_rows import _jacobian


@jit()
def task_residual(ee, ee_R, J, task, weight, position, tool_axis, rotation, axis):
    """(A, r): the task's Jacobian rows and its residual at the end-effector pose (ee, ee_R).

    Position rows: J_v and x_r − x [m]. A pose task adds w·J_ω and w·φ, φ ≈ the rotation
    vector from R to R_r (the skew part of R_r Rᵀ); a position+axis task adds
    w·(I − a aᵀ) J_ω and w·(a × a_r) (turning the tool axis a onto the reference axis a_r;
    spin about a changes nothing). w: the orientation weight of g [m/rad].

    Args:
        ee: end-effector position, shape (3,) [m].
        ee_R: end-effector rotation in the world, shape (3, 3).
        J: end-effector Jacobian, world axes, linear rows first, shape (6, nq).
        task: the task's code (0 position, 1 pose, 2 position+axis).
        weight: w of the orientation term [m/rad].
        position: the reference position x_r, shape (3,) [m].
        tool_axis: the tool axis in the end-effector frame, shape (3,).
        rotation: the reference rotation R_r (pose task), shape (3, 3).
        axis: the reference axis a_r in the world (axis task), shape (3,).

    Returns:
        A, shape (3 or 6, nq) [m/rad], and r, shape (3 or 6,) [m].
    """
    n = J.shape[1]
    rows = 3 if task == 0 else 6
    A = np.zeros((rows, n))
    r = np.zeros(rows)
    A[:3] = J[:3]
    for i in range(3):
        r[i] = position[i] - ee[i]
    if task == 1:
        M = rotation @ ee_R.T
        r[3] = 0.5 * weight * (M[2, 1] - M[1, 2])
        r[4] = 0.5 * weight * (M[0, 2] - M[2, 0])
        r[5] = 0.5 * weight * (M[1, 0] - M[0, 1])
        A[3:] = weight * J[3:]
    elif task == 2:
        a = ee_R @ tool_axis
        r[3] = weight * (a[1] * axis[2] - a[2] * axis[1])
        r[4] = weight * (a[2] * axis[0] - a[0] * axis[2])
        r[5] = weight * (a[0] * axis[1] - a[1] * axis[0])
        across = np.eye(3) - np.outer(a, a)
        A[3:] = weight * (across @ J[3:])
    return A, r


@jit()
def newton_candidate(q, A, r, damping, lower, upper):
    """The damped least-squares step from q within the box [lower, upper]: Δq =
    Aᵀ(AAᵀ + μ²I)⁻¹ r over the joints still free; a joint the step would take past its bound is
    held there and the step solved again for the rest (the residual less the held joints'
    part), until none is (at most nq rounds: an active-set pass of bounded least squares);
    the step merely clipped into the box instead where that one fits the model better.

    Args:
        q: joint angles, inside [lower, upper], shape (nq,) [rad].
        A: the task's Jacobian rows, shape (m, nq) [m/rad].
        r: the task residual, shape (m,) [m].
        damping: μ [m], > 0.
        lower: lower bound of the period's box, shape (nq,) [rad].
        upper: upper bound of the period's box, shape (nq,) [rad].

    Returns:
        The candidate joint angles, inside [lower, upper], shape (nq,) [rad].
    """
    n, m = q.size, r.size
    free = np.ones(n, dtype=np.bool_)
    step = np.zeros(n)
    clipped = step
    for round_ in range(n):
        rest = r.copy()  # the residual the free joints must still take up
        for j in range(n):
            if not free[j]:
                for i in range(m):
                    rest[i] -= A[i, j] * step[j]
        M = np.zeros((m, m))
        for i in range(m):
            for k in range(m):
                for j in range(n):
                    if free[j]:
                        M[i, k] += A[i, j] * A[k, j]
            M[i, i] += damping * damping
        y = _solve_spd(M, rest)
        held = False
        for j in range(n):
            if free[j]:
                total = 0.0
                for i in range(m):
                    total += A[i, j] * y[i]
                step[j] = total
                if q[j] + step[j] > upper[j] or q[j] + step[j] < lower[j]:
                    step[j] = min(max(q[j] + step[j], lower[j]), upper[j]) - q[j]
                    free[j] = False
                    held = True
        if round_ == 0:
            clipped = step.copy()  # the first round's step, clipped: the plain projection
        if not held:
            break
    if _model_cost(A, r, damping, clipped) < _model_cost(A, r, damping, step):
        return q + clipped  # holding joints can do worse (none is ever released): keep the best
    return q + step


@jit()
def _model_cost(A, r, damping, step):
    """|A Δq − r|² + μ²|Δq|², what the damped step minimises."""
    total = 0.0
    for i in range(r.size):
        residual = -r[i]
        for j in range(step.size):
            residual += A[i, j] * step[j]
        total += residual * residual
    for j in range(step.size):
        total += damping * damping * step[j] * step[j]
    return total


@jit()
def penalty_flat(d: float, lambda_weight: float, beta: float, flat_slope: float) -> bool:
    """Whether the penalty Λ/d^β of Eq. (1.7) is flat at clearance d: its slope Λβ/d^(β+1)
    below flat_slope, so that g is the task error for a step's purposes (changes 6 and 7:
    a step that ignores the penalty is safe to try only there).

    Args:
        d: the smallest link-obstacle clearance [m] (inf: no obstacle counts).
        lambda_weight: Λ [m^(1+β)].
        beta: β [-].
        flat_slope: the slope below which the penalty counts as flat [-].

    Returns:
        True where the penalty's slope is below flat_slope (always without a penalty or an
        obstacle that counts), never for flat_slope = 0.
    """
    if flat_slope <= 0.0:
        return False
    if lambda_weight == 0.0 or d == math.inf:
        return True
    # Λβ/d^(β+1) < slope without the division (a tiny d would underflow it to 0).
    return d > 0.0 and lambda_weight * beta < flat_slope * d ** (beta + 1.0)


@jit()
def newton_from_chain(q, reference, clearance, damping, lower, upper):
    """The Gauss-Newton candidate from q, its Jacobian from the compiled chain.

    Args:
        q: joint angles, inside [lower, upper], shape (nq,) [rad].
        reference: the period's target (baornn_kernel.Reference).
        clearance: the compiled scene, packed (its chain gives the kinematics).
        damping: μ [m], > 0.
        lower: lower bound of the period's box, shape (nq,) [rad].
        upper: upper bound of the period's box, shape (nq,) [rad].

    Returns:
        The candidate joint angles (newton_candidate), shape (nq,) [rad].
    """
    chain = named_inputs(clearance).chain
    oR, op = _joint_poses(q, chain)
    ee, ee_R = _ee_pose(oR, op, chain)
    J = _jacobian(oR, op, chain, chain.ee_joint, ee, q.size)
    r = reference
    A, residual = task_residual(
        ee, ee_R, J, r.task, r.weight, r.position, r.tool_axis, r.rotation, r.axis
    )
    return newton_candidate(q, A, residual, damping, lower, upper)


@jit()
def _solve_spd(M, b):
    """x with M x = b for a small symmetric positive definite M (Cholesky, no LAPACK call)."""
    m = b.size
    L = np.zeros((m, m))
    for i in range(m):
        for j in range(i + 1):
            total = M[i, j]
            for k in range(j):
                total -= L[i, k] * L[j, k]
            L[i, j] = math.sqrt(total) if i == j else total / L[j, j]
    y = np.empty(m)
    for i in range(m):
        total = b[i]
        for k in range(i):
            total -= L[i, k] * y[k]
        y[i] = total / L[i, i]
    x = np.empty(m)
    for i in range(m - 1, -1, -1):
        total = y[i]
        for k in range(i + 1, m):
            total -= L[k, i] * x[k]
        x[i] = total / L[i, i]
    return x
