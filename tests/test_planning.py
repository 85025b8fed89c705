"""BAORNN groundwork (chapter 1): trajectories, the objective of Eq. (1.13), Algorithm 1."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.geometry.poses import pose
from articula.geometry.shapes import sphere
from articula.planning.baornn import Baornn, BaornnParams
from articula.planning.objective import Objective
from articula.planning.track import track
from articula.planning.trajectories import Circle, Waypoints, rectangle
from articula.robots import RobotModel
from articula.scene import Obstacle, Scene

ROBOT = RobotModel.builtin("iiwa14")
CIRCLE = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)


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


def test_waypoints_interpolate_and_validate(tmp_path: Path):
    path = Waypoints.create([[0, 0, 0], [1, 2, 3]], [0.0, 2.0])
    assert np.allclose(path(1.0), [0.5, 1.0, 1.5])
    assert np.allclose(path(5.0), [1, 2, 3])  # held after the last point
    with pytest.raises(ConfigError):
        Waypoints.create([[0, 0, 0], [1, 2, 3]], [1.0, 1.0])
    csv = tmp_path / "path.csv"
    csv.write_text("t,x,y,z\n0,0,0,0\n1,1,0,0\nnan,2,0,0\n")
    with pytest.raises(ConfigError):
        Waypoints.from_csv(csv)
    csv.write_text("t,x,y,z\n0,0,0,0\n1,1,0,0\n")
    assert np.allclose(Waypoints.from_csv(csv)(0.5), [0.5, 0, 0])


def test_objective_is_tracking_error_plus_inverse_distance_penalty():
    scene = Scene(ROBOT, [Obstacle("ball", (sphere(0.1),), pose([0.4, 0.3, 0.6]))])
    q = np.array([0.1, 0.4, 0.0, -1.0, 0.0, 0.5, 0.0])
    x_ref = np.array([0.3, 0.2, 0.7])
    error = np.linalg.norm(x_ref - ROBOT.ee_position(q))
    assert Objective(scene, 0.0).value(q, x_ref) == pytest.approx(error)
    d = scene.min_distance(q)
    assert Objective(scene, 0.01, 2.0).value(q, x_ref) == pytest.approx(error + 0.01 / d**2)


def test_projection_clips_to_limits_and_refuses_points_too_close():
    scene = Scene(ROBOT, [Obstacle("ball", (sphere(0.1),), pose([0.4, 0.3, 0.6]))])
    objective = Objective(scene, 0.001, 1.0, d_min=0.05)
    current, x_ref = np.zeros(7), np.array([0.3, 0.2, 0.7])
    g_current = objective.value(current, x_ref)
    far = np.full(7, 10.0)
    q, g = objective.project_and_value(far, current, g_current, x_ref, 0.0)
    assert np.allclose(q, ROBOT.upper)
    assert g == pytest.approx(objective.value(ROBOT.upper, x_ref))
    near = np.array([0.6, 1.0, 0.0, -0.6, 0.0, 0.0, 0.0])
    assert scene.min_distance(near) < 0.05
    q, g = objective.project_and_value(near, current, g_current, x_ref, 0.0)
    assert q is current and g == g_current  # Eq. (1.17): stay where you are


def test_objective_never_increases_within_a_period():
    # Theorem 1.1: g_{k+1} <= g_k for a fixed reference.
    planner = Baornn(Objective(Scene(ROBOT, []), 0.0), BaornnParams(), np.random.default_rng(3))
    q, x_ref = np.zeros(7), np.array([0.3, 0.5, 0.6])
    g = planner.objective.value(q, x_ref)
    for _ in range(200):
        q, g_next = planner.iterate(q, g, x_ref, 0.0)
        assert g_next <= g
        assert np.all(q >= ROBOT.lower) and np.all(q <= ROBOT.upper)
        g = g_next
    assert g < 0.01  # and it gets close to a reachable point


def test_same_seed_same_trajectory_and_tracking_converges():
    def run(seed: int):
        planner = Baornn(Objective(Scene(ROBOT, []), 0.0), BaornnParams(0.3, 0.5, 10),
                         np.random.default_rng(seed))  # fmt: skip
        return track(planner, CIRCLE, np.zeros(7), 0.01, 6.0)

    a, b, c = run(0), run(0), run(1)
    assert np.array_equal(a.q, b.q)
    assert not np.array_equal(a.q, c.q)
    assert (
        np.sqrt(np.mean(a.error[a.t > 5.0] ** 2)) < 2e-3
    )  # starting from home, away from the path


def test_start_inside_d_min_is_refused():
    scene = Scene(ROBOT, [Obstacle("ball", (sphere(0.1),), pose([0.0, 0.0, 1.0]))])
    planner = Baornn(Objective(scene, 0.001, d_min=0.002), BaornnParams(), np.random.default_rng(0))
    with pytest.raises(InfeasibleError):
        track(planner, CIRCLE, np.zeros(7), 0.01, 0.1)
