"""control/chamber_allocation.py: a side's pressures push as one chamber toward it, and the body
bends the other way."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.control.chamber_allocation import bend_direction, side_pressures
from articula.plants.six_chamber import chamber_directions


@pytest.mark.parametrize("side", [0.0, 17.0, 30.0, 60.0, 215.0, -40.0])
def test_side_pressures_push_as_one_chamber(side):
    pressures = side_pressures(side, 1.0)
    assert np.all(pressures >= 0) and np.count_nonzero(pressures) <= 2
    assert pressures.max() <= 1.0 + 1e-12
    force = pressures @ chamber_directions()
    np.testing.assert_allclose(force, [math.cos(math.radians(side)), math.sin(math.radians(side))],
                               atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(bend_direction(side), -force, atol=1e-12)
