"""book/ch2/analysis.py: Table 2.3's numbers and the chapter's claims, on made-up inputs."""

import math

import numpy as np
import pytest

from articula.book.ch2 import analysis
from articula.book.ch2.book_values import BOOK_TABLE_2_3, CONTROLLERS, FREQUENCIES
from articula.errors import ConfigError

GROW = 10.0 + 5.0 * np.arange(len(FREQUENCIES))
FALL = 50.0 - 5.0 * np.arange(len(FREQUENCIES))
FLAT = np.full(len(FREQUENCIES), 20.0)
# Lower is better: automatic below manual, scheduled below ordinary.
GOOD = {"ordinary-manual": 6, "piecewise-manual": 4, "fuzzy-manual": 4,
        "ordinary-auto": 3, "piecewise-auto": 1, "fuzzy-auto": 1}  # fmt: skip
BAD = {"ordinary-manual": 1, "piecewise-manual": 4, "fuzzy-manual": 4,
       "ordinary-auto": 3, "piecewise-auto": 6, "fuzzy-auto": 6}  # fmt: skip


def _verdicts(table, kd_status="reproduced"):
    return {c.name: c.verdict for c in analysis.claims(table, kd_status)}


def test_claims_keep_their_names_and_order(table_of):
    table = table_of(dict.fromkeys(CONTROLLERS, GROW))
    assert list(_verdicts(table)) == [
        "automatic_beats_manual", "piecewise_fuzzy_beat_ordinary",
        "error_grows_with_frequency", "kd_zero_optimal",
    ]  # fmt: skip


def test_claims_are_reproduced_on_a_table_that_shows_them(table_of):
    claims = analysis.claims(table_of({n: GROW + GOOD[n] for n in CONTROLLERS}), "reproduced")
    assert all(c.verdict == "reproduced" for c in claims)
    assert "21 of 21" in claims[0].ours and "28 of 28" in claims[1].ours


def test_claims_are_not_reproduced_on_a_table_that_contradicts_them(table_of):
    verdicts = _verdicts(table_of({n: FALL + BAD[n] for n in CONTROLLERS}), "not reproduced")
    assert set(verdicts.values()) == {"not reproduced"}


def test_ties_count_for_neither_and_a_flat_table_shows_no_growth(table_of):
    verdicts = _verdicts(table_of(dict.fromkeys(CONTROLLERS, FLAT)))
    assert verdicts["automatic_beats_manual"] == "not reproduced"
    assert verdicts["piecewise_fuzzy_beat_ordinary"] == "not reproduced"
    assert verdicts["error_grows_with_frequency"] == "not reproduced"


def test_automatic_needs_more_than_half_of_the_pairs(table_of):
    med = dict.fromkeys(CONTROLLERS, FLAT)
    med["ordinary-auto"] = FLAT - 1  # 7 of 21
    med["piecewise-auto"] = FLAT - np.r_[np.ones(3), np.zeros(4)]  # 10 of 21
    assert analysis.auto_wins(table_of(med)) == (10, 21)
    assert _verdicts(table_of(med))["automatic_beats_manual"] == "not reproduced"
    med["fuzzy-auto"] = FLAT - np.r_[1.0, np.zeros(6)]  # 11 of 21
    assert _verdicts(table_of(med))["automatic_beats_manual"] == "reproduced"


def test_scheduled_needs_more_than_half_of_the_comparisons(table_of):
    # Scheduled controllers win exactly 14 of 28 (manual all, auto none): not more than half.
    med = {**dict.fromkeys(CONTROLLERS, FLAT), "ordinary-manual": FLAT + 1,
           "ordinary-auto": FLAT - 1}  # fmt: skip
    assert analysis.scheduled_wins(table_of(med)) == (14, 28)
    assert _verdicts(table_of(med))["piecewise_fuzzy_beat_ordinary"] == "not reproduced"
    med["ordinary-auto"] = FLAT.copy()
    med["ordinary-auto"][0] += 1  # one more win: 15 of 28
    assert _verdicts(table_of(med))["piecewise_fuzzy_beat_ordinary"] == "reproduced"


def test_growth_needs_every_controller_correlated(table_of):
    med = dict.fromkeys(CONTROLLERS, GROW)
    assert analysis.rank_correlations(table_of(med)) == dict.fromkeys(CONTROLLERS, 1.0)
    med = {**med, "fuzzy-auto": np.r_[GROW[:-2], GROW[-2:] - 30]}  # falls at the top
    rho = analysis.rank_correlations(table_of(med))
    assert rho["fuzzy-auto"] < analysis.GROWTH_CORRELATION
    assert _verdicts(table_of(med))["error_grows_with_frequency"] == "not reproduced"


@pytest.mark.parametrize("status", ["reproduced", "not reproduced", "inconclusive"])
def test_kd_claim_takes_the_probe_status_as_its_verdict(table_of, status):
    verdicts = _verdicts(table_of(dict.fromkeys(CONTROLLERS, GROW)), status)
    assert verdicts["kd_zero_optimal"] == status


def test_an_unknown_kd_status_is_refused(table_of):
    with pytest.raises(ConfigError) as exc:
        analysis.claims(table_of(dict.fromkeys(CONTROLLERS, GROW)), "maybe")
    assert exc.value.field == "kd_status"


def test_lowest_medians_per_frequency(table_of):
    med = {n: GROW + GOOD[n] for n in CONTROLLERS}
    assert analysis.lowest_medians(table_of(med)) == dict(zip(FREQUENCIES, GROW + 1, strict=True))


def test_the_books_misprint_is_found():
    (bad,) = analysis.misprints(BOOK_TABLE_2_3)
    assert (bad.controller, bad.frequency, bad.row) == ("fuzzy-auto", 5.0, (45.14, 41.80, 39.42))
    assert analysis.misprints({"x": [(2.0, 1.0, 3.0)] * len(FREQUENCIES)}) == []


def test_a_still_actuator_scores_two_amplitudes_over_pi():
    assert analysis.still_error(45.0) == pytest.approx(90 / math.pi)


def test_spans_count_the_book_medians_above_a_still_actuator(table_of):
    table = table_of({n: GROW + GOOD[n] for n in CONTROLLERS})
    book = {"a": [(30.0, 0, 0)] * len(FREQUENCIES), "b": [(20.0, 0, 0)] * len(FREQUENCIES)}
    two, five = analysis.spans(table, book, still=25.0)
    assert two.frequency == 2.0 and two.ours == (GROW[5] + 1, GROW[5] + 6)
    assert two.book == (20.0, 30.0) and (two.book_above_still, two.book_count) == (1, 2)
    assert five.frequency == 5.0


def test_amplitude_and_lag_of_a_known_sinusoid(sinusoid_trace):
    ratio, lag = analysis.amplitude_and_lag(sinusoid_trace(0.5, 0.6, 0.4), 0.5)
    assert ratio == pytest.approx(0.6) and lag == pytest.approx(0.4)


def test_json_tables_keep_their_shape(table_of):
    table = table_of(dict.fromkeys(CONTROLLERS, GROW))
    data = analysis.table_data(table)
    assert list(data) == list(CONTROLLERS)
    assert data["fuzzy-auto"]["0.05"] == [10.0, 9.0, 11.0] and list(data["fuzzy-auto"])[-1] == "5"
    assert analysis.gain_dict(np.array([1.0, 2.0, 0.0])) == {"kp": 1.0, "ki": 2.0, "kd": 0.0}


def test_findings_of_made_up_results(made_up):
    results = made_up(missed=True)
    f = analysis.findings(results)
    assert f.kd_status == "reproduced" and list(f.kd) == ["automatic sequence", "manual 90"]
    assert f.missed == ("15",) and f.manual_kd["90"] == (0.01,)
    assert f.descent["sequence"].moved and f.descent["sequence"].final == 0.04
    assert f.still == pytest.approx(90 / math.pi) and len(f.misprints) == 1
    assert f.calibration[0.05] == pytest.approx((0.5, 0.3))
    assert f.zn_kp_ratio == pytest.approx(0.6 * 7.11 / 1.27)


def test_tuning_data_has_every_run(made_up):
    tuning = made_up().tuning
    data = analysis.tuning_data(tuning.manual, tuning.auto)
    assert list(data["manual"]) == ["90", "15", "45", "75"]
    assert list(data["auto"]) == ["sequence", "15", "45", "75"]
    assert data["auto"]["15"] == {"kp": 0.64, "ki": 1.21, "kd": 0.165}
