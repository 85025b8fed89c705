"""planning/slide.py: the correction that brings a step back above its floors is the least-task-
motion point of the linearised feasible set (against scipy's SLSQP), keeps the tangential part
of a step that crosses one boundary, and says when no correction in the box exists; with it a
resolved-rate arm whose link reaches d_min slides along it where, without, it froze, and
baornn-improved's sliding step (change 8) takes it past a pair held at self_d_min."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from articula.bench import suite
from articula.bench.problems import D_MIN
from articula.planning import resolved_rate
from articula.planning.baornn_improved import ImprovedBaornn
from articula.planning.clearance import ClearanceRows
from articula.planning.slide import JOINT_WEIGHT, SLIDE_BAND, SLIDE_MARGIN, slide_correction

FLOORS = (0.002, 0.005)  # (d_min, self_d_min) [m]


def _rows(distance, gradient, self_pair=None) -> ClearanceRows:
    distance = np.asarray(distance, dtype=float)
    if self_pair is None:
        self_pair = np.zeros(distance.size, dtype=bool)
    return ClearanceRows(distance, np.asarray(gradient, dtype=float), np.asarray(self_pair))


def _oracle(rows, low, high, J):
    """SLSQP on the same problem: min |JΔ|² + w|Δ|² over the near rows' half-spaces and box."""
    floor = np.where(rows.self_pair, FLOORS[1], FLOORS[0]) + SLIDE_MARGIN
    near = rows.distance < floor + SLIDE_BAND
    A, need = rows.gradient[near], (floor - rows.distance)[near]
    H = J.T @ J + JOINT_WEIGHT * np.eye(low.size)
    result = minimize(
        lambda x: x @ H @ x,
        np.clip(np.zeros(low.size), low, high),
        jac=lambda x: 2 * H @ x,
        bounds=list(zip(low, high, strict=True)),
        constraints=[{"type": "ineq", "fun": lambda x: A @ x - need, "jac": lambda x: A}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    )
    assert result.success
    return result.x, H


@pytest.mark.parametrize("seed", range(20))
def test_the_correction_is_the_least_task_motion_point_of_the_linearised_set(seed):
    rng = np.random.default_rng(seed)
    n, m = 7, int(rng.integers(1, 5))
    J = rng.normal(size=(3, n))
    gradient = rng.normal(scale=0.3, size=(m, n))
    self_pair = rng.random(m) < 0.3
    floor = np.where(self_pair, FLOORS[1], FLOORS[0])
    distance = floor + rng.uniform(-3e-3, 0.5e-3, size=m)  # some below, some just above
    rows = _rows(distance, gradient, self_pair)
    low, high = np.full(n, -0.05), np.full(n, 0.05)
    correction = slide_correction(rows, FLOORS, low, high, J)
    assert correction is not None
    expected, H = _oracle(rows, low, high, J)
    near = distance < floor + SLIDE_MARGIN + SLIDE_BAND
    # Feasible: every near row ends at least SLIDE_MARGIN above its floor (to first order).
    reached = distance[near] + gradient[near] @ correction
    assert np.all(reached >= floor[near] + SLIDE_MARGIN - 1e-9)
    assert np.all(correction >= low - 1e-12) and np.all(correction <= high + 1e-12)
    # Optimal: no higher cost than SLSQP's point.
    assert correction @ H @ correction <= expected @ H @ expected * (1 + 1e-6) + 1e-15


def test_a_step_across_one_boundary_keeps_its_tangential_part():
    # The joints move the task one to one (J = I); the boundary's normal is joint 0. A step
    # that crossed it by 1 mm is pushed back along the normal only.
    J = np.eye(3)
    rows = _rows([FLOORS[0] - 1e-3], [[1.0, 0.0, 0.0]])
    correction = slide_correction(rows, FLOORS, np.full(3, -1.0), np.full(3, 1.0), J)
    assert correction is not None
    assert correction[0] == pytest.approx(1e-3 + SLIDE_MARGIN, rel=1e-6)
    assert np.abs(correction[1:]).max() < 1e-12  # the motion along the boundary survives


def test_no_row_near_its_floor_needs_no_correction():
    rows = _rows([0.05, 0.004 + FLOORS[1] + SLIDE_MARGIN], np.ones((2, 4)), [False, True])
    correction = slide_correction(rows, FLOORS, -np.ones(4), np.ones(4), np.eye(4)[:3])
    assert np.array_equal(correction, np.zeros(4))


def test_a_row_below_its_floor_that_no_joint_moves_has_no_correction():
    # A table under a fixed base: its distance does not depend on q.
    rows = _rows([0.001], np.zeros((1, 4)))
    assert slide_correction(rows, FLOORS, -np.ones(4), np.ones(4), np.eye(4)[:3]) is None


def test_a_box_too_small_to_reach_the_floor_has_no_correction():
    rows = _rows([FLOORS[0] - 0.01], [[1.0, 0.0, 0.0]])
    box = np.full(3, 1e-3)  # 1 mrad of room, 10 mm to recover at 1 m/rad
    assert slide_correction(rows, FLOORS, -box, box, np.eye(3)) is None


@pytest.fixture
def grazing_problem(tmp_path):
    """Task of solve_problem for grazing problem 1 of seed 0 (iiwa14): the obstacle-free motion
    of its links passes within d_min of a ball; pinv without the slide stalls there."""
    return {"robot": {"builtin": "iiwa14"}, "seed": 0, "index": 1, "class": "grazing",
            "methods": ["pinv"], "key": "test", "folder": str(tmp_path / "p1")}  # fmt: skip


def test_a_link_held_at_d_min_slides_along_it_and_the_arm_tracks(grazing_problem):
    (row,) = suite.solve_problem(grazing_problem)[1]
    assert row["success"], row
    assert row["colliding_steps"] == 0
    # It moved along the boundary (its closest link within 0.1 mm of d_min) without stopping.
    assert D_MIN <= row["min_clearance"] < D_MIN + 1e-4
    assert row["stalled_s"] == 0.0


def test_without_the_slide_the_same_arm_freezes_at_d_min(grazing_problem, monkeypatch):
    # The case is hard: the step check alone (halvings toward braking) holds the link at d_min.
    monkeypatch.setattr(resolved_rate, "SLIDES", 0)
    (row,) = suite.solve_problem(grazing_problem)[1]
    assert row["failure"] == "tracking"
    assert row["min_clearance"] == pytest.approx(D_MIN, abs=1e-5)
    assert row["stalled_s"] > 1.0


@pytest.fixture
def held_at_self_d_min(tmp_path):
    """Task of solve_problem for grazing problem 16 of seed 0 (iiwa14), where baornn-improved's
    search alone holds links 5 and 7 at self_d_min, 4 mm RMS off the path."""
    return {"robot": {"builtin": "iiwa14"}, "seed": 0, "index": 16, "class": "grazing",
            "methods": ["baornn-improved"], "key": "test",
            "folder": str(tmp_path / "p16")}  # fmt: skip


@pytest.mark.slow
def test_baornn_improved_slides_along_self_d_min_where_its_search_alone_is_held(
    held_at_self_d_min, monkeypatch
):
    (row,) = suite.solve_problem(held_at_self_d_min)[1]
    assert row["success"], row
    monkeypatch.setattr(ImprovedBaornn, "_slide", lambda self, q, g, target, t: (q, g))
    (alone,) = suite.solve_problem(held_at_self_d_min)[1]
    assert alone["failure"] == "tracking" and alone["rms_error"] > 3e-3
    assert row["colliding_steps"] == alone["colliding_steps"] == 0
