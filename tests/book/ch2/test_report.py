"""book/ch2/report.py: the section's tables, notes and figure links from made-up results."""

import re

import pytest

from articula.book.ch2 import analysis, report
from articula.book.ch2.book_values import CONTROLLERS
from articula.book.ch2.study import KD_PROBE

FIGURES = ["fig2_5", "fig2_6", "fig2_7", "fig2_8", "fig2_9", "fig2_10"]


@pytest.fixture
def section(made_up):
    """The markdown of made-up results in which the 15° manual run missed its tolerance."""
    results = made_up(missed=True)
    return report.markdown(results, analysis.findings(results))


def test_sections_come_in_order(section):
    headings = re.findall(r"^### (.*)$", section, flags=re.MULTILINE)
    assert headings == [
        "Tuning (Sect. 2.3.2, 2.4.2.1): Table 2.2, Figs. 2.5 and 2.6",
        "Comparison (Sect. 2.4.2.2): Table 2.3, Figs. 2.7-2.10",
        "Is K_d = 0 optimal? (Sect. 2.4.2.1)",
    ]


def test_every_figure_is_linked_once(section):
    links = re.findall(r"!\[[^\]]*\]\((ch2/[^)]+)\)", section)
    assert links == [f"ch2/{name}.png" for name in FIGURES]


def test_table_2_2_rows_put_ours_beside_the_books(section):
    assert "| 15 | 1.9, 0.76, 0 | 1, 1, 0 | 0.64, 1.21, 0.165 | 1, 2.44, 0 | 13 / 70 |" in section
    assert "| 90 (Fig. 2.5) | 1.27, 2.56, 0 | not printed | — | — | 15 / — |" in section
    assert "| 15→45→75→90 (Fig. 2.6a) | — | — | 0.87, 5.44, 0.04 | 0.5, 1.86, 0 | — / 64 |" in (
        section
    )


def test_a_missed_tolerance_is_named(section):
    assert "did not bring the steady-state error within 1° at 15°" in section


def test_table_2_3_marks_the_lowest_median_and_shows_the_books(section):
    header = "| f [Hz] | " + " | ".join(CONTROLLERS) + " |"
    assert header in section
    row = "| 0.05 | 16.00 (15.00, 17.00) / 19.03 | 14.00 (13.00, 15.00) / 12.29 |"
    assert section.count(row) == 1
    assert "**11.00** (10.00, 12.00) / 11.41 | **11.00** (10.00, 12.00) / 9.79 |" in section


def test_notes_on_table_2_3(section):
    assert "fuzzy-auto at 5 Hz (median 45.14, Q1 41.80, Q3 39.42)" in section
    assert "E = 2A/π = 28.6°" in section and "worse than not moving" in section
    assert "0.05 Hz: 0.50, 17°, 5 Hz: 0.50, 17°." in section
    assert "10 trials" in section and "±5 % σ" in section
    assert "`articula sweep ch2/table2_3_sweep.toml --out DIR`" in section


def test_kd_table_has_a_column_per_probed_k_d(section):
    header = "| gain set | " + " | ".join(f"K_d = {kd:g}" for kd in KD_PROBE)
    assert header in section
    assert "| manual 90 | 19.95 (0) | 21.95 (0) |" in section
    assert "| 0 | none | 0.02, 0.05, 0.1, 0.2 |" in section
    assert "4 of 4 runs ended at K_d > 0 (the book's ended at 0) and 1 never moved K_d" in section
    assert "75: 0.1 → 0.1 (never moved), step dK_d 0.05 → 0.01" in section
    assert "90°: tried 0.01, kept 0" in section


def test_the_claims_list_is_left_to_the_shared_block(section):
    assert "**Reproduced.**" not in section and "claims against" not in section


def test_gains_to_three_significant_digits():
    assert report.gains([1.2345, 0.0, 10.0]) == "1.23, 0, 10"
