"""Chapter 3's claim rules and derived numbers, on made-up inputs."""

from __future__ import annotations

import math

import pytest

from articula.book.ch3 import analysis
from articula.book.ch3.book_values import CLAIM_BOOK, CLAIM_GROWS
from articula.book.ch3.searches import DirectionRow
from articula.book.ch3.what_ifs import Outcome, StiffeningRow, ValveCase

from .conftest import FREE, delta_sweep, timing_sweep


def verdicts(peak, settling) -> dict[str, str]:
    return {c.name: c.verdict for c in analysis.claims(delta_sweep(peak, settling))}


# ----- "damping grows with delta" ----------------------------------------------------------------


def test_grows_when_peak_and_settling_fall_and_the_peak_halves():
    assert verdicts([19.0, 12.0, 9.0], [0.9, 0.7, 0.5])[CLAIM_GROWS] == "reproduced"


def test_grows_tolerates_sensor_noise():
    peak = [19.0, 19.0 + 0.9 * analysis.PEAK_TOL, 9.0]
    settle = [0.9, 0.9 + 0.9 * analysis.SETTLE_TOL, 0.5]
    assert analysis.damping_grows(peak, settle)


def test_does_not_grow_when_the_peak_rises():
    assert verdicts([18.7, 18.4, 19.9], [0.98, 0.98, 0.98])[CLAIM_GROWS] == "not reproduced"


def test_does_not_grow_when_the_peak_is_not_halved():
    assert not analysis.damping_grows([19.0, 15.0, 10.0], [0.9, 0.8, 0.7])


def test_a_run_that_never_settles_does_not_grow():
    assert not analysis.damping_grows([19.0, 12.0, 9.0], [0.9, 0.7, None])


def test_grows_is_inconclusive_with_one_delta():
    assert verdicts([19.0], [0.9])[CLAIM_GROWS] == "inconclusive"


# ----- "about 2 deg and 0.5 s near delta = 0.5" --------------------------------------------------


def test_book_values_at_delta_one_half_are_reproduced():
    peak = [19.0, 15.0, 10.0, 6.0, 3.0, 2.0]
    settle = [0.9, 0.8, 0.7, 0.6, 0.55, 0.45]
    assert verdicts(peak, settle)[CLAIM_BOOK] == "reproduced"


@pytest.mark.parametrize(("peak", "settling"), [(3.5, 0.5), (2.0, 0.7), (2.0, None)])
def test_book_values_missed_at_delta_one_half(peak, settling):
    peaks = [19.0, 18.0, 18.0, 18.0, 18.0, peak]
    settle = [0.9, 0.9, 0.9, 0.9, 0.9, settling]
    assert verdicts(peaks, settle)[CLAIM_BOOK] == "not reproduced"


def test_book_values_inconclusive_without_a_delta_near_one_half():
    assert verdicts([19.0, 2.0, 2.0], [0.9, 0.5, 0.5])[CLAIM_BOOK] == "inconclusive"


def test_claims_keep_todays_names_and_state_their_numbers():
    claims = analysis.claims(delta_sweep([18.7, 18.4, 19.9], [0.98, 0.98, None]))
    assert [c.name for c in claims] == [CLAIM_GROWS, CLAIM_BOOK]
    assert "18.70°" in claims[0].ours and "—" in claims[0].ours  # never settles: a dash


def test_meets_book_is_one_sided_in_the_peak():
    assert analysis.meets_book(0.0, 0.5)
    assert not analysis.meets_book(2.0, 0.5 + 1.01 * analysis.BOOK_SETTLING_TOL_S)
    assert not analysis.meets_book(2.0, math.nan)


# ----- derived numbers ---------------------------------------------------------------------------


def test_body_overshoot_is_one_undamped_and_falls_with_damping():
    assert analysis.body_overshoot(0.0) == 1.0
    assert analysis.body_overshoot(0.1) == pytest.approx(0.7292, abs=1e-4)


def test_sensitivity_holds_unless_some_case_meets_the_book():
    missed = ValveCase("a", FREE, Outcome(19.0, 0.9, 31.0))
    met = ValveCase("b", FREE, Outcome(2.0, 0.5, 31.0))
    assert analysis.sensitivity_holds([missed])
    assert not analysis.sensitivity_holds([missed, met])


def test_stiffening_helps_only_if_a_pulse_halves_its_rows_peak():
    row = StiffeningRow(0.5, (Outcome(10.0, 0.8, 20.0), Outcome(6.0, 0.7, 20.0), FREE))
    assert not analysis.stiffening_helps([row])
    halved = StiffeningRow(1.0, (Outcome(10.0, 0.8, 20.0), Outcome(5.0, 0.7, 20.0), FREE))
    assert analysis.stiffening_helps([row, halved])


def test_timing_summary_picks_best_calm_and_the_books_corner():
    s = analysis.timing_summary(timing_sweep(), undamped_peak_deg=19.0)
    assert s.best == 2  # 0.3 s, NaN ignored
    assert s.calm == 2  # 19.05° is within PEAK_TOL of 19°
    assert s.early == 1  # first start, longest length
    assert s.lowest_peak_deg == 18.0


def test_timing_summary_calm_skips_pulses_that_raise_the_first_swing():
    s = analysis.timing_summary(timing_sweep(), undamped_peak_deg=18.9)
    assert s.calm == 0


def rows(between: float) -> list[DirectionRow]:
    return [
        DirectionRow(0.0, "side 0", Outcome(19.0, 0.2, 31.0)),
        DirectionRow(60.0, "side 0", Outcome(19.0, 0.2, 31.0)),
        DirectionRow(30.0, "side 0", Outcome(19.0, between, 31.0)),
        DirectionRow(30.0, "own", Outcome(19.0, 9.0, 31.0)),
        DirectionRow(30.0, "none", Outcome(19.0, 9.0, 31.0)),
    ]


def test_similar_between_chambers_within_the_factor():
    assert analysis.similar_between_chambers(rows(analysis.SIMILAR * 0.2))
    assert not analysis.similar_between_chambers(rows(analysis.SIMILAR * 0.21))


def test_findings_of_made_up_results(results):
    f = analysis.findings(results)
    assert f.period_s == pytest.approx(2 * math.pi / 30.0)
    assert f.too_fast == [False, True, False]  # 0, 5 and 10 ms against 10 ms
    assert f.open_ms == pytest.approx((5.0, 10.0))
    assert f.reduction == pytest.approx(1 - 18.4 / 18.7)
    assert f.fastest == 0 and not f.grows
    assert f.sensitivity_holds and not f.stiffening_helps and not f.similar
