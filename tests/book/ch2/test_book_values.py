"""book/ch2/book_values.py: the book's tables have the shape the study and report assume."""

from articula.book.ch2.book_values import (
    BOOK_TABLE_2_2,
    BOOK_TABLE_2_3,
    CONTROLLERS,
    FIG_2_6,
    FREQUENCIES,
    SINUSOID_FIGURES,
)
from articula.book.ch2.tuning import SUBRANGES


def test_controllers_are_table_2_3s_columns_in_order():
    assert CONTROLLERS == (
        "ordinary-manual", "piecewise-manual", "fuzzy-manual",
        "ordinary-auto", "piecewise-auto", "fuzzy-auto",
    )  # fmt: skip
    assert list(BOOK_TABLE_2_3) == list(CONTROLLERS)


def test_table_2_3_has_a_median_and_quartiles_per_frequency():
    for rows in BOOK_TABLE_2_3.values():
        assert len(rows) == len(FREQUENCIES) and all(len(row) == 3 for row in rows)


def test_table_2_2_has_a_gain_row_per_subrange_and_the_sequence():
    points = [f"{p:g}" for p in SUBRANGES]
    assert list(BOOK_TABLE_2_2["manual"]) == points
    assert list(BOOK_TABLE_2_2["auto"]) == [*points, "sequence"]
    assert set(FIG_2_6) == {*points, "sequence"}


def test_sinusoid_figures_are_at_table_2_3_frequencies():
    assert set(SINUSOID_FIGURES) <= set(FREQUENCIES)
    assert [stem for stem, _ in SINUSOID_FIGURES.values()] == ["fig2_7", "fig2_8", "fig2_9"]
