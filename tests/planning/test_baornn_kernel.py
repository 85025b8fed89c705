"""planning/baornn_kernel.py: the compiled iterations of both BAORNN variants follow their Python
loops (coal distances) step by step on the book's two-obstacle scene."""

from __future__ import annotations

import numpy as np

from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.baornn_improved import ImprovedBaornn, ImprovedParams
from articula.planning.objective import Objective
from tests.planning.helpers import CIRCLE, ROBOT
from tests.scene.helpers import book_scene


def _both_paths(make_planner, periods: int) -> tuple[np.ndarray, list]:
    """q after each of `periods` control periods of 10 ms along the book circle, from home, for
    the planner make_planner(objective, rng) on the compiled and on the coal objective (Λ =
    0.005, β = 1, d_min = 2 mm, seed 4); returns both q series and both planners."""
    scene = book_scene("circle_two_obstacles")
    runs, planners = [], []
    for compiled in (True, False):
        objective = Objective(scene, 0.005, 1.0, 0.002, use_compiled=compiled)
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
    # gradient estimate carries into q at ~1e-9 rad over the first steps.
    params = ImprovedParams(c1=0.3, c2=0.5, pairs=3, iterations_per_step=2)
    runs, planners = _both_paths(lambda objective, rng: ImprovedBaornn(objective, params, rng), 20)
    for planner in planners:
        assert planner.iterations == 40
    assert np.allclose(runs[0], runs[1], atol=1e-6)
