"""tuning/coordinate_descent.py: coordinate descent (chapter 2, Algorithm 1): hand-traced steps,
monotone cost, a known bowl."""

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
    ("kwargs", "field"),
    [
        ({"k0": [0.0, 1.0], "dk0": [0.1]}, "dk0"),
        ({"dk0": [-0.1, 0.1]}, "dk0"),
        ({"dk0": [np.inf, 0.1]}, "dk0"),
        ({"k0": [np.nan, 0.0]}, "k0"),
        ({"k0": [[0.0, 0.0]], "dk0": [[0.1, 0.1]]}, "k0"),
        ({"k_stop": np.nan}, "k_stop"),
        ({"k_stop": -1.0}, "k_stop"),
        ({"max_iterations": 0}, "max_iterations"),
        ({"max_iterations": 2.5}, "max_iterations"),
        ({"lower": np.zeros(3)}, "lower"),
        ({"upper": np.ones((2, 1))}, "upper"),
        ({"lower": np.ones(2), "upper": np.zeros(2)}, "upper"),
        ({"k0": [5.0, 0.0], "upper": np.ones(2)}, "k0"),
    ],
)
def test_bad_arguments_are_config_errors_naming_the_field(kwargs, field):
    args = {"k0": [0.0, 0.0], "dk0": [0.1, 0.1], "k_stop": 0.0, "max_iterations": 1, **kwargs}
    args["k0"], args["dk0"] = np.array(args["k0"]), np.array(args["dk0"])
    with pytest.raises(ConfigError) as exc:
        coordinate_descent(lambda k: 0.0, **args)
    assert exc.value.field == field, exc.value


def test_history_is_read_only_and_keeps_the_start():
    k0 = np.array([0.0, 1.0])
    res = coordinate_descent(lambda k: float(k @ k), k0, np.array([0.5, 0.5]), 0.0, 3)
    k0[0] = 99.0  # the caller's array is copied
    assert res.history[0].k.tolist() == [0.0, 1.0]
    for array in (res.k, res.history[-1].k, res.history[-1].dk):
        with pytest.raises(ValueError):
            array[0] = 1.0
