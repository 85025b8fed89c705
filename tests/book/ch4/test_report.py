"""Chapter 4's report formats made-up results: tables, figure links and verdict-decided text."""

from __future__ import annotations

import dataclasses
import re

import pytest

from articula.book.ch4 import analysis, report
from tests.book.ch4.conftest import GAINS

REPRODUCED = dict.fromkeys(
    (analysis.OMEGA_C, analysis.PER_VOLT, analysis.RISE_TIME, analysis.TRACKS,
     analysis.AMPLITUDE_FALLS, analysis.LAG_GROWS, analysis.FEEDBACK_RISE,
     analysis.CURRENT_RISE, analysis.FILTER_COSTS, analysis.LESS_NOISE,
     analysis.LESS_BANDWIDTH),
    "reproduced",
)  # fmt: skip
NONE_REPRODUCED = dict.fromkeys(REPRODUCED, "not reproduced")
INCONCLUSIVE = dict.fromkeys(REPRODUCED, "inconclusive")


def markdown(results, verdicts) -> str:
    why = analysis.explanations(GAINS, results.runs, results.bandwidth)
    return report.markdown(results, why, verdicts)


@pytest.fixture
def differs(results) -> str:
    return markdown(results, NONE_REPRODUCED)


@pytest.fixture
def agrees(results) -> str:
    return markdown(results, REPRODUCED)


def test_every_section_and_figure_link_is_there(differs):
    for heading in (
        "### Motor model (Sect. 4.2) and critical speed (Sect. 4.3.2)",
        "### Fig. 4.3: current against speed at 12 V",
        "### Figs. 4.5-4.9: PI + feed-forward current control on the dual-motor rig",
        "### The chapter's question: bandwidth against filter order, and what it buys",
    ):
        assert heading in differs
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", differs)
    assert links == ["ch4/fig4_3.png", "ch4/fig4_5.png", "ch4/fig4_6.png", "ch4/fig4_7.png",
                     "ch4/fig4_8.png", "ch4/fig4_9.png", "ch4/bandwidth.png"]  # fmt: skip


def test_model_table_puts_the_book_beside_ours(differs):
    assert "| ω_ss / V, Eq. (4.8), Table 4.1 [rad/(s·V)] | 2.81 | 2.5469 |" in differs
    assert "| ω_c at 12 V and 1 A, Table 4.2 [rad/s] | 8.1382 | 8.1382 |" in differs
    assert "ω = 30.563 rad/s, i = 0.13775 A |" in differs
    assert "| > i_ss(τ_ex = 0) | 0.9018 |" in differs
    assert "Current falls linearly from 1.437 A at standstill to 0 at 26.76 rad/s" in differs


def test_run_table_has_one_row_per_figure_with_milli_units_and_dashes(differs):
    assert (
        "| Fig. 4.5: constant reference, unfiltered | 1 | 1.0 | 1.0 | — | 20.0 | — | — | "
        "rise time ≈ 0.1 s; converges quickly; noisy sensor |" in differs
    )
    fig4_6 = "| Fig. 4.6: sinusoid at 5 rad/s, unfiltered | 1 | — | — | — | 20.0 | 0.819 | 15.5 |"
    assert fig4_6 in differs
    assert "| Fig. 4.8: constant reference, filtered | 50 | 1.0 | 28.0 |" in differs


def test_bandwidth_table_shows_above_the_sweep_and_saturation(differs):
    assert "tracking RMS error at 2 rad/s [mA]" in differs
    assert "(15 runs;" in differs
    assert "| 1 | 8.39 | 8.39 | yes | 20.6 | 10.0 | 7 % |" in differs
    assert "| 256 | > max tested | > max tested | yes | 1.4 | 10.0 | 37 % |" in differs
    assert "For k = 1, 256 the driver sits at full PWM more than 5 % of the time" in differs


def test_explanations_appear_only_where_a_claim_is_not_reproduced(differs, agrees):
    explanations = (
        "do not follow from Table 4.1 through Eq. (4.8)",
        "The constant bias of Eq. (4.13) puts the full voltage",
        "ours loses 18 % because",
        "The amplitude does not fall from 5 rad/s.",
        "the loop tends to its proportional gain 0.54",
        "The feed-forward bias drives the current up regardless",
        "a moving average of order 50 delays the feedback by 24.5 ms",
        "The bandwidth does not fall as k grows.",
        "not monotonically",
    )
    for text in explanations:
        assert text in differs, text
        assert text not in agrees, text
    assert "Tracked closely." in agrees
    assert "falling monotonically." in agrees


def test_an_inconclusive_claim_gets_no_explanation_of_a_difference(results):
    text = markdown(results, INCONCLUSIVE)
    assert "The constant bias of Eq. (4.13) puts the full voltage" not in text


def test_numbers_in_the_explanations_come_from_the_results(results):
    model = dataclasses.replace(results.model, denominator=0.2, omega_per_volt=2.0)
    text = markdown(dataclasses.replace(results, model=model), NONE_REPRODUCED)
    assert "the denominator bR + K² is 0.20000, which gives 2.0000 V" in text


def test_no_claims_list_in_the_section(differs):
    assert "**Agrees" not in differs and "**Differs" not in differs
    assert "claims" not in differs.lower()
