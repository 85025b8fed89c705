"""planning/newton_step.py: baornn-improved's Gauss-Newton candidate against numpy's and scipy's
least squares, and its task residual against Pinocchio's log map on the iiwa14."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import lsq_linear

from articula.planning import newton_step
from articula.planning.newton_step import penalty_flat
from articula.planning.reference_velocity import rotation_vector
from tests.planning.helpers import ROBOT

RNG_SEED = 11
TOOL_AXIS = np.array([0.0, 0.0, 1.0])


def _cost(A, r, damping, step):
    """|A Δq − r|² + μ²|Δq|²: what the damped step minimises."""
    return float(np.sum((A @ step - r) ** 2) + damping**2 * np.sum(step**2))


def test_the_cholesky_solve_matches_numpy():
    rng = np.random.default_rng(RNG_SEED)
    for m in (3, 6):
        for _ in range(20):
            B = rng.standard_normal((m, m))
            M, b = B @ B.T + 0.01 * np.eye(m), rng.standard_normal(m)
            assert np.allclose(newton_step._solve_spd(M, b), np.linalg.solve(M, b), rtol=1e-9)


def test_in_a_wide_box_the_candidate_is_the_damped_least_squares_step():
    rng = np.random.default_rng(RNG_SEED)
    q, wide = np.zeros(7), np.full(7, 10.0)
    for m in (3, 6):
        A, r = rng.standard_normal((m, 7)), 0.01 * rng.standard_normal(m)
        step = newton_step.newton_candidate(q, A, r, 0.02, -wide, wide) - q
        # Both forms of the damped least squares: Aᵀ(AAᵀ + μ²I)⁻¹r = (AᵀA + μ²I)⁻¹Aᵀr.
        assert np.allclose(step, A.T @ np.linalg.solve(A @ A.T + 0.02**2 * np.eye(m), r))
        assert np.allclose(step, np.linalg.solve(A.T @ A + 0.02**2 * np.eye(7), A.T @ r))


def test_in_a_tight_box_the_candidate_stays_inside_and_beats_clipping():
    # Oracle: scipy's exact bounded least squares (BVLS) on the damped system [A; μI] Δq ≈ [r; 0].
    rng = np.random.default_rng(RNG_SEED)
    better = optimal = 0
    for _ in range(200):
        A, r = rng.standard_normal((3, 7)), 0.05 * rng.standard_normal(3)
        q = rng.uniform(-0.5, 0.5, 7)
        low, high = q - rng.uniform(0.0, 0.01, 7), q + rng.uniform(0.0, 0.01, 7)
        step = newton_step.newton_candidate(q, A, r, 0.02, low, high) - q
        assert np.all(q + step >= low - 1e-15) and np.all(q + step <= high + 1e-15)
        free = A.T @ np.linalg.solve(A @ A.T + 0.02**2 * np.eye(3), r)
        clipped = np.clip(q + free, low, high) - q
        assert _cost(A, r, 0.02, step) <= _cost(A, r, 0.02, clipped) + 1e-15
        better += _cost(A, r, 0.02, step) < _cost(A, r, 0.02, clipped) * (1 - 1e-9)
        best = lsq_linear(np.vstack([A, 0.02 * np.eye(7)]), np.r_[r, np.zeros(7)],
                          bounds=(low - q, high - q), method="bvls").x  # fmt: skip
        assert _cost(A, r, 0.02, step) >= _cost(A, r, 0.02, best) * (1 - 1e-9)
        optimal += _cost(A, r, 0.02, step) <= _cost(A, r, 0.02, best) * (1 + 1e-6) + 1e-15
    # Boxes 0-1 cm wide, most joints bound: holding beats clipping in 134 of the 200 and is
    # the optimum in 65 (clipping in 7); one pass that never releases a joint is not BVLS.
    assert better > 100 and optimal > 40, (better, optimal)


def test_the_position_residual_is_the_jacobian_and_the_offset():
    q = np.array([0.3, -0.4, 0.2, -1.1, 0.5, 0.6, -0.2])
    pose, J = ROBOT.ee_pose(q), ROBOT.jacobian(q)
    target = pose[:3, 3] + [0.01, -0.02, 0.005]
    A, r = newton_step.task_residual(pose[:3, 3].copy(), np.ascontiguousarray(pose[:3, :3]), J,
                                     0, 0.1, target, TOOL_AXIS, np.eye(3), TOOL_AXIS)  # fmt: skip
    assert np.array_equal(A, J[:3]) and np.allclose(r, [0.01, -0.02, 0.005])


@pytest.mark.parametrize("task", [1, 2])
def test_one_orientation_step_on_the_iiwa_removes_most_of_a_small_error(task):
    # Pose (1) and position+axis (2): the residual is w times Pinocchio's log of the error to
    # first order, and one undamped-enough step from q removes > 95 % of a 20 mrad error.
    q = np.array([0.3, -0.4, 0.2, -1.1, 0.5, 0.6, -0.2])
    pose = ROBOT.ee_pose(q)
    R = np.ascontiguousarray(pose[:3, :3])
    turn = pin.exp3(np.array([0.012, -0.008, 0.013]))  # 20 mrad about a world axis
    R_ref = turn @ R
    axis_ref = R_ref @ TOOL_AXIS
    weight = 0.1

    def error(q_now):
        R_now = ROBOT.ee_pose(q_now)[:3, :3]
        if task == 1:
            return float(np.linalg.norm(pin.log3(R_ref @ R_now.T)))
        return float(np.arccos(np.clip(R_now @ TOOL_AXIS @ axis_ref, -1, 1)))

    A, r = newton_step.task_residual(pose[:3, 3].copy(), R, ROBOT.jacobian(q), task, weight,
                                     pose[:3, 3].copy(), TOOL_AXIS, R_ref, axis_ref)  # fmt: skip
    if task == 1:
        assert np.allclose(r[3:], weight * pin.log3(turn), rtol=1e-3)
    else:  # the shortest rotation taking the tool axis onto the reference (sin θ ≈ θ)
        assert np.allclose(r[3:], weight * rotation_vector(R @ TOOL_AXIS, axis_ref), rtol=1e-3)
    wide = np.full(7, 10.0)
    q_new = newton_step.newton_candidate(q, A, r, 1e-4, q - wide, q + wide)
    assert error(q_new) < 0.05 * error(q)
    assert np.linalg.norm(ROBOT.ee_position(q_new) - pose[:3, 3]) < 1e-4  # the tool stays


def test_the_penalty_is_flat_where_its_slope_is_below_the_threshold():
    # Λβ/d^(β+1): Λ = 0.005, β = 1 has slope 0.1 at d = √0.05 = 0.2236 m.
    assert not penalty_flat(0.22, 0.005, 1.0, 0.1)
    assert penalty_flat(0.23, 0.005, 1.0, 0.1)
    assert penalty_flat(0.001, 0.0, 1.0, 0.1)  # no penalty
    assert penalty_flat(np.inf, 0.005, 1.0, 0.1)  # no obstacle counts
    assert not penalty_flat(0.0, 0.005, 1.0, 0.1)  # touching
    assert not penalty_flat(10.0, 0.005, 1.0, 0.0)  # 0: never flat
    assert not penalty_flat(np.inf, 0.005, 1.0, 0.0) and not penalty_flat(0.5, 0.0, 1.0, 0.0)
    assert not penalty_flat(1e-170, 0.005, 1.0, 0.1)  # no division to underflow
