"""Chapter 3's coordinate-descent searches and damping in any direction."""

from __future__ import annotations

import pytest

from articula.book.ch3 import searches
from articula.book.ch3.what_ifs import outcome
from articula.control.damping import DampingPolicy
from articula.errors import ConfigError


def test_pulse_data_holds_the_searched_parameters_only():
    policy = DampingPolicy(delta=0.4, start=0.1)
    assert searches.Pulse(policy, ("delta",), 0.8, 5, 18.0).data() == {
        "delta": 0.4, "settling_s": 0.8, "peak_deg": 18.0, "evaluations": 5,
    }  # fmt: skip
    assert list(searches.Pulse(policy, searches.TIMED, 0.8, 5).data()) == [
        "delta", "start", "length", "settling_s", "evaluations",
    ]  # fmt: skip


def test_settling_cost_is_the_true_angles_settling():
    assert searches.settling_cost(0.0, 0.0, 0.0) == outcome().settling_s


def test_book_timing_search_stays_in_bounds():
    found = searches.book_timing(iterations=1)
    assert 0 <= found.policy.delta <= searches.DELTA_MAX
    assert found.policy.start == 0.0 and found.policy.length == 0.0
    assert 1 <= found.evaluations <= 3  # the start and at most two probes
    assert found.settling_s <= searches.settling_cost(*searches.BOOK_K0, 0.0, 0.0)


def test_directions_apply_the_side_0_pulse_to_every_side_in_order():
    policy = DampingPolicy(delta=0.3, start=0.15, length=0.045)
    d = searches.directions(policy, iterations=1)
    assert [r.side_deg for r in d.rows] == sorted(r.side_deg for r in d.rows)
    assert {r.side_deg for r in d.rows if r.pulse == "side 0"} == set(searches.SIDES)
    assert [r.side_deg for r in d.rows if r.pulse == "own"] == [searches.SIDE_DEG]
    by = {(r.side_deg, r.pulse): r.outcome for r in d.rows}
    first, sixty = by[(0.0, "side 0")], by[(60.0, "side 0")]  # six-fold symmetry
    assert sixty.peak_deg == pytest.approx(first.peak_deg, rel=1e-12)
    assert sixty.settling_s == first.settling_s
    assert d.own.peak_deg is None


def test_compared_policies_start_with_the_undamped_run():
    book = searches.Pulse(DampingPolicy(delta=0.49), ("delta",), 0.9, 1)
    best = searches.Pulse(DampingPolicy(delta=0.2, start=0.1), searches.TIMED, 0.2, 1)
    policies = searches.compared(book, best)
    assert policies["undamped"] == DampingPolicy()
    assert policies["best δ and timing"] is best.policy


def test_a_search_needs_at_least_one_iteration():
    with pytest.raises(ConfigError) as exc:
        searches.timed(0)
    assert exc.value.field == "max_iterations"
