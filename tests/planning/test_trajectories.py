"""planning/trajectories.py: the circle of Eq. (1.27), the book's rectangle at constant speed, and
waypoints interpolated from lists or a CSV file, with their refusals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.planning.trajectories import Circle, Waypoints, rectangle
from tests.planning.helpers import CIRCLE


def test_circle_follows_eq_1_27():
    assert np.allclose(CIRCLE(0.0), [0.2, 0.6, 0.5])
    assert np.allclose(CIRCLE(12.5), [0.0, 0.6, 0.7])  # a quarter period: C + r B
    assert np.allclose(CIRCLE(50.0), CIRCLE(0.0))
    assert np.allclose(np.linalg.norm(CIRCLE(7.3) - CIRCLE.center), 0.2)


def test_circle_rejects_axes_that_are_not_orthonormal():
    with pytest.raises(ConfigError):
        Circle.create([0, 0, 0], [1, 0, 0], [1, 1, 0], 0.2, 10.0)


def test_rectangle_visits_the_book_vertices_at_constant_speed():
    vertices = [[0.2, 0.6, 0.8], [-0.1, 0.6, 0.8], [-0.1, 0.6, 0.2], [0.2, 0.6, 0.2]]
    path = rectangle(vertices, 50.0)
    # Perimeter 1.8 m: the first corner after 0.3 m, i.e. 50 s · 0.3 / 1.8.
    assert np.allclose(path(50.0 * 0.3 / 1.8), vertices[1])
    assert np.allclose(path(0.0), vertices[0]) and np.allclose(path(50.0), vertices[0])
    speeds = np.linalg.norm(np.diff([path(t) for t in np.linspace(0, 50, 501)], axis=0), axis=1)
    assert np.allclose(speeds, 1.8 / 500, atol=1e-9) or speeds.max() <= 1.8 / 500 + 1e-9


def test_waypoints_interpolate_and_hold_the_last_point():
    path = Waypoints.create([[0, 0, 0], [1, 2, 3]], [0.0, 2.0])
    assert np.allclose(path(1.0), [0.5, 1.0, 1.5])
    assert np.allclose(path(5.0), [1, 2, 3])  # held after the last point


def test_waypoint_times_must_increase():
    with pytest.raises(ConfigError):
        Waypoints.create([[0, 0, 0], [1, 2, 3]], [1.0, 1.0])


def test_waypoints_from_csv(tmp_path: Path):
    csv = tmp_path / "path.csv"
    csv.write_text("t,x,y,z\n0,0,0,0\n1,1,0,0\nnan,2,0,0\n")
    with pytest.raises(ConfigError):
        Waypoints.from_csv(csv)
    csv.write_text("t,x,y,z\n0,0,0,0\n1,1,0,0\n")
    assert np.allclose(Waypoints.from_csv(csv)(0.5), [0.5, 0, 0])
