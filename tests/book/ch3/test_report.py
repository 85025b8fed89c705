"""Chapter 3's report formats made-up results: tables, figure links and number-decided text."""

from __future__ import annotations

import dataclasses

import pytest

from articula.book.ch3 import analysis, report


@pytest.fixture
def text(results) -> str:
    return report.markdown(results, analysis.findings(results))


def test_every_section_and_figure_link_is_there(text):
    for heading in (
        "### The actuator model and its calibration",
        "### Fig. 3.7: deactuation against the damping actuation ratio δ",
        "### What the opposite chamber can do",
        "### Which timing of the opposite pulse damps",
        "### Beyond the book: the δ and pulse timing that minimise settling time",
        "### Beyond the book: damping in any bending direction",
    ):
        assert heading in text
    for link in ("![Fig. 3.7](ch3/fig3_7.png)", "![pulse timing](ch3/timing.png)",
                 "![best pulse](ch3/search.png)"):  # fmt: skip
        assert link in text


def test_the_claims_list_is_left_to_the_shared_block(text):
    assert "Claims of Sect. 3.4" not in text
    assert "**false**" not in text


def test_fig_3_7_rows_flag_open_times_a_solenoid_cannot_switch(text):
    assert "| 0 | 0.0 | 18.70 | 60.0 | 0.980 | about 18-20 | about 0.9-1 |" in text
    assert "| 0.1 | 5.0 † | 18.40 | 60.0 | 0.980 | — | — |" in text
    assert "| 0.2 | 10.0 | 19.90 | 60.0 | — | — | — |" in text  # never settles: a dash
    assert "† Open time below 10 ms" in text


def test_book_values_stand_beside_delta_one_half(results):
    sweep = dataclasses.replace(results.delta, delta=[0.0, 0.1, 0.5])
    text = report.markdown(dataclasses.replace(results, delta=sweep), analysis.findings(results))
    assert "| about 2 | about 0.5 |" in text


def test_calibration_command_names_the_new_module(text):
    assert "`articula.book.ch3.calibration.calibrate`" in text
    assert "articula.experiments" not in text


def test_sensitivity_rows_and_verdict(text):
    assert "| orifice 0.5 mm | 19.00° / 0.900 s | 19.50° / — s |" in text
    assert "so the verdict below does not depend on them" in text


def test_mechanism_verdict_differs_when_damping_does_not_grow(text):
    assert "**Differs** from the book: a pulse at the vent command" in text
    assert "(5-10 ms against a period of 0.209 s)" in text
    assert "18.70° at δ = 0 to 18.40° at δ = 0.1 (2 % less" in text


def test_mechanism_verdict_agrees_when_damping_grows(results):
    f = dataclasses.replace(analysis.findings(results), grows=True)
    assert "**Agrees** with the book" in report.markdown(results, f)


def test_stiffening_row(text):
    assert "| 0 | 19.00° / 0.900 s | 19.00° / 0.960 s | 33.00° / 1.100 s |" in text
    assert "does not let the pulse at the vent command halve the peak" in text


def test_timing_bullets(text):
    assert "(4 runs)" in text
    assert "start 0.150 s, length 0.000 s: 0.300 s with 19.05° past rest" in text
    assert "(start 0 s, length 0.1 s): 1.000 s with 25.00° past rest" in text
    assert "Lowest first swing on the grid: 18.00°" in text


def test_search_table(text):
    assert "| δ only, book timing | 0.490 | 0.000 | 0.000 | 0.885 | 18.97 | 22 |" in text
    assert "| δ, start, length | 0.200 | 0.130 | 0.080 | 0.200 | 19.00 | 71 |" in text
    assert "quick mode: at most 12 sweeps" in text


def test_direction_table_and_search(text):
    assert "| 30 | timed pulse found for side 0° | 31.00 | 19.70 | 0.400 |" in text
    assert "| 30 | timed pulse found for side 30° | 31.00 | 19.70 | 0.190 |" in text
    assert "chamber 0 settles more slowly between chambers." in text
    assert "finds δ = 0.180, start 0.134 s, length 0.070 s: settling 0.190 s." in text
