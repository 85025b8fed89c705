"""plants/orientation_sensor.py: roll-pitch-yaw from the bending vector and back, and the
sensor's sampling rate and noise."""

from __future__ import annotations

import numpy as np
import pytest

from articula.plants.orientation_sensor import (
    OrientationSensorParams,
    bend_from_euler,
    euler_from_bend,
    read,
)

IDEAL = OrientationSensorParams(ideal=True)


def test_euler_angles_round_trip():
    rng = np.random.default_rng(3)
    beta = rng.uniform(-0.8, 0.8, (200, 2))
    np.testing.assert_allclose(bend_from_euler(euler_from_bend(beta)), beta, atol=1e-12)
    pure_x = euler_from_bend(np.array([[0.3, 0.0]]))[0]  # tilt toward +x is a pitch
    np.testing.assert_allclose(pure_x, [0.0, 0.3, 0.0], atol=1e-12)


def test_sensor_rate_and_noise():
    t = np.arange(0, 2.0 + 1e-9, 1e-3)
    beta = np.zeros((t.size, 2))
    params = OrientationSensorParams(rate=50.0, noise_deg=0.5)
    ts, euler = read(params, t, beta, np.random.default_rng(0))
    assert ts.size == 101 and np.allclose(np.diff(ts), 0.02)
    assert np.degrees(euler.std()) == pytest.approx(0.5, rel=0.1)
    ts, euler = read(IDEAL, t, beta, np.random.default_rng(0))
    assert ts.size == t.size and not euler.any()
