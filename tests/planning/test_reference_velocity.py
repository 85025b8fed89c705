"""planning/reference_velocity.py: the feed-forward of the reference's own motion plus a
proportional correction, with no steady lag on a moving reference."""

from __future__ import annotations

import numpy as np
import pytest

from articula.planning.reference_velocity import reference_velocity


def test_reference_velocity_without_a_previous_point_is_proportional():
    x, x_ref = np.array([0.1, 0.2, 0.3]), np.array([0.4, -0.1, 0.5])
    assert np.allclose(reference_velocity(x_ref, None, x, 0.01, 7.0), 7.0 * (x_ref - x))


@pytest.mark.parametrize("gain", [5.0, 20.0, 150.0])
def test_reference_velocity_has_no_steady_lag_on_a_straight_line(gain):
    # A perfect integrator x_{n+1} = x_n + dt v_n after each period ending at ref(t_n), as in
    # track(): the recorded error |x_{n+1} - ref(t_n)| must vanish, not settle at |u| dt.
    dt, u = 0.01, np.array([0.3, -0.2, 0.1])  # 0.37 m/s: one period's travel is 3.7 mm
    ref = lambda t: np.array([0.1, 0.5, 0.4]) + u * t  # noqa: E731
    x, previous, errors = np.array([0.0, 0.4, 0.6]), None, []
    for n in range(400):
        x_ref = ref(n * dt)
        x = x + dt * reference_velocity(x_ref, previous, x, dt, gain)
        previous = x_ref
        errors.append(np.linalg.norm(x - x_ref))
    assert errors[0] > 0.1  # it started off the line
    assert max(errors[-50:]) < 1e-6
    assert np.linalg.norm(u) * dt > 1e-3  # a one-period lag would have been visible
