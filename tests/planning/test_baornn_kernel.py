"""planning/baornn_kernel.py: the compiled iterations of both BAORNN variants follow their Python
loops (coal distances) step by step on the book's two-obstacle scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from articula.planning import baornn_kernel
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.baornn_improved import ImprovedBaornn, ImprovedParams
from articula.planning.objective import Objective
from articula.planning.task import as_target
from articula.scene.config import build_scene, load_scene_spec
from articula.scene.scene import Scene
from tests.planning.helpers import CIRCLE, ROBOT, ball
from tests.scene.helpers import book_scene

BALL = ([0.35, 0.35, 0.6], 0.08)  # beside the elbow on the way to the circle


def _both_paths(
    make_planner, periods: int, penalty: float = 0.005, scene: Scene | None = None
) -> tuple[np.ndarray, list]:
    """q after each of `periods` control periods of 10 ms along the book circle, from home, for
    the planner make_planner(objective, rng) on the compiled and on the coal objective (Λ =
    `penalty`, β = 1, d_min = 2 mm, seed 4) of `scene` (None: the book's two obstacles);
    returns both q series and both planners."""
    scene = scene or book_scene("circle_two_obstacles")
    runs, planners = [], []
    for compiled in (True, False):
        objective = Objective(scene, penalty, 1.0, 0.002, use_compiled=compiled)
        planner = make_planner(objective, np.random.default_rng(4))
        q = np.zeros(ROBOT.nq)
        qs = []
        for n in range(periods):
            q = planner.step(q, CIRCLE(0.01 * n), 0.01 * n)
            qs.append(q.copy())
        runs.append(np.array(qs))
        planners.append(planner)
    return np.array(runs), planners


def test_compiled_baornn_follows_the_python_loop():
    params = BaornnParams(c1=0.3, c2=0.5, iterations_per_step=10)
    runs, planners = _both_paths(lambda objective, rng: Baornn(objective, params, rng), 60)
    for planner in planners:
        assert planner.iterations == 600 and planner.evaluations == 1800
    # The two distance codes agree to ~1e-7 m, so the accepted steps are the same ones.
    assert np.allclose(runs[0], runs[1], atol=1e-6)


def test_compiled_improved_variant_follows_its_python_loop():
    # The same draws and steps; the two distance codes differ by ~1e-7 m, which a continuous
    # gradient estimate carries into q at ~1e-9 rad over the first steps and ~2e-6 rad over
    # twenty (a different acceptance would differ by the antennae, ~1e-2 rad).
    params = ImprovedParams(c1=0.3, c2=0.5, pairs=3, iterations_per_step=2)
    runs, planners = _both_paths(lambda objective, rng: ImprovedBaornn(objective, params, rng), 20)
    for planner in planners:
        assert planner.iterations == 40
    assert np.allclose(runs[0][:4], runs[1][:4], atol=1e-8)
    assert np.allclose(runs[0], runs[1], atol=1e-5)


def test_compiled_newton_candidate_and_quiet_stop_follow_the_python_loop():
    # Λ = 5e-5 beside a ball ≥ 66 mm away: the penalty is flat beyond 22 mm, so changes 6
    # and 7 act; the Jacobians (compiled chain, Pinocchio) agree to round-off.
    params = ImprovedParams(c1=0.3, c2=0.5, pairs=3, iterations_per_step=4)
    runs, planners = _both_paths(
        lambda objective, rng: ImprovedBaornn(objective, params, rng), 300, 5e-5, ball(*BALL)
    )
    assert planners[0].iterations == planners[1].iterations < 1000  # periods stopped
    assert planners[0].evaluations == planners[1].evaluations
    assert np.allclose(runs[0], runs[1], atol=1e-6)


def test_a_point_closer_to_itself_than_the_margin_is_outside_omega_on_every_path():
    robot = {"builtin": "iiwa14", "self_collision": True}
    scene, _ = build_scene(load_scene_spec({"robot": robot}), Path("."))
    clear = np.array([0.0, 0.6, 0.0, -1.2, 0.0, 1.0, 0.0])
    folded = np.array([0.0, 1.9, 0.0, 2.0, 0.0, 2.0, 0.0])  # links 5 and 7 overlap
    lo, hi = 0.0, 1.0  # bisect to a point 20-80 µm from contact, inside the margin
    for _ in range(60):
        mid = (lo + hi) / 2
        d = scene.self_clearance(clear + mid * (folded - clear))
        if 2e-5 < d < 8e-5:
            break
        lo, hi = (mid, hi) if d > 0 else (lo, mid)
    q = clear + mid * (folded - clear)
    assert 0.0 < scene.self_clearance(q) < baornn_kernel.SELF_CONTACT_MARGIN
    target = as_target(np.array([0.0, 0.6, 0.5]))
    for compiled in (True, False):
        objective = Objective(scene, 0.0, 1.0, 0.0, use_compiled=compiled)
        kept, g = objective.project_and_value(q, clear, 7.0, target, 0.0)
        assert np.array_equal(kept, clear) and g == 7.0
    objective = Objective(scene, 0.0, 1.0, 0.0)
    reference = baornn_kernel.Reference(*objective.reference(target))
    problem = baornn_kernel.Problem(*objective.problem())
    kept, g, _ = baornn_kernel._project_and_value(q, clear, 7.0, 0.5, reference, problem)
    assert np.array_equal(kept, clear) and g == 7.0
