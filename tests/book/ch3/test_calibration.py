"""Chapter 3's calibration of E and b to the book's undamped deactuation."""

from __future__ import annotations

import pytest

from articula.book.ch3.calibration import calibrate, undamped
from articula.plants.six_chamber import SixChamberParams

P = SixChamberParams()


@pytest.mark.slow
def test_defaults_reproduce_the_books_undamped_deactuation():
    m = undamped(P)
    assert 18.0 <= m["peak_true_deg"] <= 20.0
    # "about 0.9 s" (Sect. 3.1) and "about 1 s" (Sect. 3.4); settling is a staircase in b.
    assert 0.85 <= m["settling_true_s"] <= 1.05


@pytest.mark.slow
def test_calibration_returns_the_defaults():
    c = calibrate()
    assert c.youngs_modulus == pytest.approx(P.youngs_modulus, rel=0.01)
    assert c.damping == pytest.approx(P.damping, rel=0.02)
