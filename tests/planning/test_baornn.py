"""planning/baornn.py: Algorithm 1 never increases the objective within a period (Theorem 1.1),
is deterministic for a seed and converges onto the book circle; its parameters are checked."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.loops.tracking import track
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.objective import Objective
from tests.planning.helpers import CIRCLE, FREE, ROBOT


def test_objective_never_increases_within_a_period():
    # Theorem 1.1: g_{k+1} <= g_k for a fixed reference.
    planner = Baornn(Objective(FREE, 0.0), BaornnParams(), np.random.default_rng(3))
    q, x_ref = np.zeros(7), np.array([0.3, 0.5, 0.6])
    g = planner.objective.value(q, x_ref)
    for _ in range(200):
        q, g_next = planner.iterate(q, g, x_ref, 0.0)
        assert g_next <= g
        assert np.all(q >= ROBOT.lower) and np.all(q <= ROBOT.upper)
        g = g_next
    assert g < 0.01  # and it gets close to a reachable point


def test_same_seed_same_trajectory_and_tracking_converges():
    def run(seed: int):
        params = BaornnParams(c1=0.3, c2=0.5, iterations_per_step=10)
        planner = Baornn(Objective(FREE, 0.0), params, np.random.default_rng(seed))
        return track(planner, CIRCLE, np.zeros(7), 0.01, 6.0)

    a, b, c = run(0), run(0), run(1)
    assert np.array_equal(a.q, b.q)
    assert not np.array_equal(a.q, c.q)
    # Starting from home, away from the path.
    assert np.sqrt(np.mean(a.error[a.t > 5.0] ** 2)) < 2e-3


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"c1": 0.0}, "BaornnParams.c1"),
        ({"c2": -0.5}, "BaornnParams.c2"),
        ({"iterations_per_step": 0}, "BaornnParams.iterations_per_step"),
        ({"pairs": 3}, "BaornnParams.pairs"),
    ],
)
def test_bad_params_name_the_class_and_field(kwargs, field):
    with pytest.raises(ConfigError) as exc:
        BaornnParams(**kwargs)
    assert exc.value.field == field


def test_params_take_keyword_arguments_only():
    with pytest.raises(TypeError):
        BaornnParams(0.3, 0.5, 10)  # type: ignore[misc]
