"""Numbers as the report prints them."""

from __future__ import annotations

import math

from articula.book.text import degrees, finite_or_none, fixed, milli, significant


def test_missing_or_non_finite_values_print_as_a_dash():
    for format_ in (lambda x: fixed(x, 2), milli, degrees):
        assert format_(None) == format_(math.nan) == format_(math.inf) == "—"
    assert significant(None) == significant(math.nan) == "—"


def test_finite_values_print_in_their_units():
    assert fixed(1.23456, 2) == "1.23"
    assert milli(0.0123) == "12.3"
    assert degrees(math.pi / 2) == "90.0"
    assert significant(12345.0) == "1.23e+04"
    assert significant(math.inf) == "> max tested"


def test_json_gets_none_for_what_it_cannot_hold():
    assert finite_or_none(math.nan) is None and finite_or_none(None) is None
    assert finite_or_none(2) == 2.0
