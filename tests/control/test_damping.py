"""control/damping.py: the opposite chambers' pulse as valve events (Eq. 3.4)."""

from __future__ import annotations

import numpy as np
import pytest

from articula.control.damping import DampingPolicy
from articula.errors import ConfigError
from articula.plants.six_chamber import SixChamberParams
from articula.plants.six_chamber_sim import FILL, HOLD, VENT, fill_time

P = SixChamberParams()


def test_no_damping_gives_no_events():
    assert DampingPolicy().events(P, np.full(6, P.supply), 1.5) == []


def test_the_pulse_fills_the_opposite_chamber_for_the_open_time_of_its_pressure():
    pressures = np.array([P.supply, 0, 0, 0, 0, 0])
    events = DampingPolicy(delta=0.5, start=0.1, length=0.2).events(P, pressures, 1.5)
    t_open = fill_time(P, 0.5 * P.supply)
    assert events == [(1.6, 3, FILL), (1.6 + t_open, 3, HOLD), (1.6 + max(0.2, t_open), 3, VENT)]


def test_a_pulse_shorter_than_its_fill_vents_only_once_filled():
    pressures = np.array([P.supply, 0, 0, 0, 0, 0])
    (fill, hold, vent) = DampingPolicy(delta=0.5, length=0.0).events(P, pressures, 1.0)
    assert vent[0] == hold[0] > fill[0]


@pytest.mark.parametrize("fields", [{"delta": 1.0}, {"delta": -0.1}, {"start": -1.0}])
def test_bad_policies_name_the_field(fields):
    with pytest.raises(ConfigError) as err:
        DampingPolicy(**fields)
    assert err.value.field.startswith("DampingPolicy.")
