"""Coordinate descent (chapter 2, Algorithm 1): hand-traced steps, monotone cost, a known bowl."""

import itertools

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.tuning.coordinate_descent import coordinate_descent


def test_one_coordinate_by_hand():
    # cost (k - 1)^2 from k = 0, dk = 0.5: +0.5 succeeds (0.25), dk -> 0.6; then 1.1 (0.01)
    # succeeds, dk -> 0.72; then 1.82 fails, 0.38 fails, dk -> 0.576.
    res = coordinate_descent(lambda k: float((k[0] - 1.0) ** 2), np.array([0.0]),
                             np.array([0.5]), k_stop=0.0, max_iterations=3)  # fmt: skip
    assert [h.k[0] for h in res.history] == pytest.approx([0.0, 0.5, 1.1, 1.1])
    assert [h.dk[0] for h in res.history] == pytest.approx([0.5, 0.6, 0.72, 0.576])
    assert [h.evaluations for h in res.history] == [1, 2, 3, 5]
    assert res.cost == pytest.approx(0.01)


def test_never_accepts_a_worse_cost_and_finds_a_convex_minimum():
    rng = np.random.default_rng(3)
    centre = np.array([2.0, -1.0, 0.5])
    weights = np.array([1.0, 4.0, 0.3])
    calls = []

    def bowl(k):
        value = float(np.sum(weights * (k - centre) ** 2))
        calls.append(value)
        return value

    res = coordinate_descent(bowl, rng.uniform(-3, 3, 3), rng.uniform(0.1, 1.0, 3),
                             k_stop=1e-6, max_iterations=500)  # fmt: skip
    bests = [h.best_cost for h in res.history]
    assert all(b2 <= b1 for b1, b2 in itertools.pairwise(bests))
    assert res.k == pytest.approx(centre, abs=1e-3)
    assert res.evaluations == len(calls)
    assert res.cost == pytest.approx(min(calls))


def test_stops_on_the_step_threshold():
    res = coordinate_descent(lambda k: float(k @ k), np.array([1.0, 1.0]), np.array([0.1, 0.1]),
                             k_stop=0.05, max_iterations=10_000)  # fmt: skip
    assert np.sum(res.history[-1].dk) < 0.05
    assert np.sum(res.history[-2].dk) >= 0.05


def test_bounds_are_never_evaluated_outside():
    seen = []

    def cost(k):
        seen.append(k.copy())
        return float((k[0] + 5.0) ** 2)  # minimum outside the bound

    res = coordinate_descent(cost, np.array([1.0]), np.array([0.4]), k_stop=1e-4,
                             max_iterations=200, lower=np.array([0.0]))  # fmt: skip
    assert min(s[0] for s in seen) >= 0.0
    assert res.k[0] == pytest.approx(0.0, abs=1e-3)


@pytest.mark.parametrize(
    ("k0", "dk0", "field"),
    [([0.0, 1.0], [0.1], "dk0"), ([0.0], [-0.1], "dk0"), ([np.nan], [0.1], "dk0")],
)
def test_bad_start_is_a_config_error(k0, dk0, field):
    with pytest.raises(ConfigError, match=field):
        coordinate_descent(lambda k: 0.0, np.array(k0), np.array(dk0), 0.0, 1)
