"""The chapter's tuning runs: the step reference and the K_d probe."""

import numpy as np
import pytest

from articula.book.ch2.tuning import KdProbe, kd_probe, step_reference
from articula.plants.pneunet import PneuNetParams


def test_step_reference_reuses_the_steps_reference():
    r = step_reference((15.0, 45.0), hold=1.0, period=1 / 30)
    assert r.tolist() == [15.0] * 30 + [45.0] * 30


def test_kd_probe_gives_every_k_d_the_same_noise():
    gains = np.array([1.0, 2.0, 0.0])
    probe = kd_probe(PneuNetParams(), gains, (45.0,), 2.0, (0.0, 0.0, 0.1), seeds=3, band=2.0)
    assert probe.cost.shape == probe.swings.shape == probe.sustained.shape == (3, 3)
    np.testing.assert_array_equal(probe.cost[0], probe.cost[1])  # same K_d, same noise
    assert not np.array_equal(probe.cost[0], probe.cost[2])
    assert len(set(probe.cost[0])) == 3  # every seed its own noise


def test_kd_probe_arrays_are_read_only():
    probe = KdProbe((0.0, 0.1), np.ones((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)))
    assert probe.sustained.dtype == bool
    for array in (probe.cost, probe.swings, probe.sustained):
        with pytest.raises(ValueError):
            array[0, 0] = 1
