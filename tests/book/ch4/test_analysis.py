"""Chapter 4's claim rules, sweep summary and explanation numbers, on made-up inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.book.ch4 import analysis
from articula.book.ch4 import book_values as book
from articula.plants.dc_motor import TABLE_4_1, steady_state

from .conftest import GAINS, ROWS, figure_runs, row

ALL = (analysis.OMEGA_C, analysis.PER_VOLT, analysis.RISE_TIME, analysis.TRACKS,
       analysis.AMPLITUDE_FALLS, analysis.LAG_GROWS, analysis.FEEDBACK_RISE,
       analysis.CURRENT_RISE, analysis.FILTER_COSTS, analysis.LESS_NOISE,
       analysis.LESS_BANDWIDTH)  # fmt: skip


def run_verdict(name: str, **changes: dict[str, float]) -> str:
    """The verdict of one figure-run claim on the made-up runs with some metrics changed."""
    return {c.name: c.verdict for c in analysis.run_claims(figure_runs(**changes))}[name]


def model_verdicts(omega_c: float, omega: float, current: float) -> dict[str, str]:
    return {c.name: c.verdict for c in analysis.model_claims(omega_c, omega, current)}


def bandwidth_verdicts(rows) -> dict[str, str]:
    return {c.name: c.verdict for c in analysis.bandwidth_claims(rows)}


def test_claims_have_the_contract_names_in_order():
    model = {"omega_c": 8.1382, "omega_ss_per_volt": 2.81, "i_ss_per_volt": 0.015}
    assert [c.name for c in analysis.claims(model, figure_runs(), ROWS)] == list(ALL)


# ----- model numbers ------------------------------------------------------------------------------


def test_omega_c_matches_within_half_the_last_digit():
    tol = analysis.OMEGA_C_TOLERANCE
    assert model_verdicts(book.OMEGA_C + 0.9 * tol, 2.81, 0.015)[analysis.OMEGA_C] == "reproduced"
    assert model_verdicts(book.OMEGA_C - 1.1 * tol, 2.81, 0.015)[analysis.OMEGA_C] == (
        "not reproduced"
    )
    assert model_verdicts(math.nan, 2.81, 0.015)[analysis.OMEGA_C] == "inconclusive"


def test_steady_state_per_volt_needs_both_numbers():
    assert model_verdicts(8.1382, 2.812, 0.0152)[analysis.PER_VOLT] == "reproduced"
    assert model_verdicts(8.1382, 2.5469, 0.0152)[analysis.PER_VOLT] == "not reproduced"
    assert model_verdicts(8.1382, 2.81, 0.011479)[analysis.PER_VOLT] == "not reproduced"
    assert model_verdicts(8.1382, 2.81, math.nan)[analysis.PER_VOLT] == "inconclusive"


def test_implied_constants_give_back_the_per_volt_numbers():
    K, b = analysis.implied_constants(TABLE_4_1.R, 2.81, 0.015)
    omega, current = steady_state(TABLE_4_1.model_copy(update={"K": K, "b": b}), 1.0)
    assert omega == pytest.approx(2.81, rel=1e-12)
    assert current == pytest.approx(0.015, rel=1e-12)


# ----- Figs. 4.5-4.9 ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("rise", "verdict"),
    [(0.1, "reproduced"), (0.05, "reproduced"), (0.2, "reproduced"), (0.001, "not reproduced"),
     (0.3, "not reproduced"), (math.nan, "inconclusive")],
)  # fmt: skip
def test_rise_time_about_0_1_s(rise, verdict):
    assert run_verdict(analysis.RISE_TIME, fig4_5={"rise_time": rise}) == verdict


@pytest.mark.parametrize(
    ("ratio", "verdict"),
    [(0.97, "reproduced"), (0.95, "reproduced"), (0.819, "not reproduced"),
     (math.nan, "inconclusive")],
)  # fmt: skip
def test_tracks_5_rad_s(ratio, verdict):
    assert run_verdict(analysis.TRACKS, fig4_6={"amplitude_ratio": ratio}) == verdict


def test_amplitude_falls_at_25_rad_s():
    name = analysis.AMPLITUDE_FALLS
    assert run_verdict(name) == "reproduced"
    assert run_verdict(name, fig4_7={"amplitude_ratio": 0.9}) == "not reproduced"
    assert run_verdict(name, fig4_7={"amplitude_ratio": math.nan}) == "inconclusive"


def test_phase_lag_grows_at_25_rad_s():
    name = analysis.LAG_GROWS
    assert run_verdict(name) == "not reproduced"
    assert run_verdict(name, fig4_7={"phase_lag": 0.5}) == "reproduced"
    assert run_verdict(name, fig4_6={"phase_lag": math.nan}) == "inconclusive"


def test_filtering_lengthens_the_fed_back_rise_time():
    name = analysis.FEEDBACK_RISE
    assert run_verdict(name) == "reproduced"
    assert run_verdict(name, fig4_8={"rise_time_feedback": 0.001}) == "not reproduced"
    assert run_verdict(name, fig4_8={"rise_time_feedback": math.nan}) == "inconclusive"


def test_filtering_lengthens_the_current_rise_time():
    name = analysis.CURRENT_RISE
    assert run_verdict(name) == "not reproduced"
    assert run_verdict(name, fig4_8={"rise_time": 0.03}) == "reproduced"
    assert run_verdict(name, fig4_5={"rise_time": math.nan}) == "inconclusive"


def test_filter_costs_magnitude_and_phase():
    name = analysis.FILTER_COSTS
    assert run_verdict(name) == "not reproduced"
    assert run_verdict(name, fig4_9={"amplitude_ratio": 0.7, "phase_lag": 0.4}) == "reproduced"
    assert run_verdict(name, fig4_9={"amplitude_ratio": 0.7}) == "not reproduced"
    assert run_verdict(name, fig4_9={"phase_lag": math.nan}) == "inconclusive"


# ----- the bandwidth sweep ------------------------------------------------------------------------


def test_noise_falls_or_stays_with_filter_order():
    assert bandwidth_verdicts(ROWS)[analysis.LESS_NOISE] == "reproduced"
    flat = [row(1, 9.0, 0.01), row(4, 8.0, 0.01)]
    assert bandwidth_verdicts(flat)[analysis.LESS_NOISE] == "reproduced"
    rising = [row(1, 9.0, 0.01), row(4, 8.0, 0.02)]
    assert bandwidth_verdicts(rising)[analysis.LESS_NOISE] == "not reproduced"
    assert bandwidth_verdicts(ROWS[:1])[analysis.LESS_NOISE] == "inconclusive"


def test_bandwidth_falls_with_filter_order():
    falling = [row(1, 9.0, 0.02), row(4, 8.0, 0.01), row(16, 3.0, 0.005)]
    assert bandwidth_verdicts(falling)[analysis.LESS_BANDWIDTH] == "reproduced"
    assert bandwidth_verdicts(ROWS)[analysis.LESS_BANDWIDTH] == "not reproduced"
    both_above = [row(1, math.inf, 0.02), row(4, math.inf, 0.01)]
    assert bandwidth_verdicts(both_above)[analysis.LESS_BANDWIDTH] == "not reproduced"
    unknown = [row(1, 9.0, 0.02), row(4, math.nan, 0.01)]
    assert bandwidth_verdicts(unknown)[analysis.LESS_BANDWIDTH] == "inconclusive"
    assert bandwidth_verdicts(ROWS[:1])[analysis.LESS_BANDWIDTH] == "inconclusive"


def sweep_table() -> dict[str, list]:
    """Two orders, two seeds, three frequencies; k = 4 is above half power everywhere."""
    table: dict[str, list] = {name: [] for name in (
        "controller.filter_order", "reference.frequency", "amplitude_ratio", "noise_rms",
        "current_rms_error", "saturation_fraction",
    )}  # fmt: skip
    ratios = {1: [1.0, 0.8, 0.5], 4: [1.0, 0.95, 0.9]}
    for k in (4, 1):
        for seed in (0, 1):
            for f, ratio in zip((2.0, 4.0, 8.0), ratios[k], strict=True):
                table["controller.filter_order"].append(k)
                table["reference.frequency"].append(f)
                table["amplitude_ratio"].append(ratio + (0.01 if seed else -0.01))
                table["noise_rms"].append(0.01 * k + 0.001 * seed)
                table["current_rms_error"].append(f / 100 + 0.002 * seed)
                table["saturation_fraction"].append(0.1 * seed + 0.01 * f)
    return table


def test_bandwidth_rows_summarise_each_order():
    rows = analysis.bandwidth_rows(sweep_table(), {1: (True, 5.0), 4: (False, 99.0)})
    assert [r.k for r in rows] == [1, 4]
    first, second = rows
    np.testing.assert_array_equal(first.frequencies, [2.0, 4.0, 8.0])
    np.testing.assert_allclose(first.ratios, [1.0, 0.8, 0.5])
    # Log-interpolated between 4 rad/s (0.8) and 8 rad/s (0.5).
    x = (analysis.HALF_POWER - 0.8) / (0.5 - 0.8)
    assert first.measured == pytest.approx(math.exp(math.log(4) + x * math.log(2)))
    assert second.measured == math.inf
    assert (first.stable, first.predicted) == (True, 5.0)
    assert not second.stable and math.isnan(second.predicted)
    assert first.noise == pytest.approx(0.0105)
    assert first.low_frequency == 2.0
    assert first.error_low == pytest.approx(0.021)
    assert first.saturation == pytest.approx(0.18)


def test_explanations_quote_the_loop_and_the_book():
    why = analysis.explanations(GAINS, figure_runs(), ROWS)
    assert why.proportional_gain == pytest.approx(10 / 18.35)
    assert why.integral_corner == pytest.approx(100 / 18.35)
    assert why.tracking_loss == pytest.approx(1 - 0.819)
    assert why.filter_order == 50
    assert why.filter_delay == pytest.approx(0.0245)
    assert why.book_ratio == pytest.approx(0.015 / 2.81)
    assert why.saturated_orders == (1, 256)
