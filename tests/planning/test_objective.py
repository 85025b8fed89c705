"""planning/objective.py: the objective (1.13) is the tracking error plus an inverse-distance
penalty; the projection (1.17) clips to the joint limits and refuses points too close, on the
compiled and the coal paths alike; scenes without a compiled form use coal."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.geometry.poses import pose
from articula.geometry.shapes import cylinder
from articula.planning.objective import Objective
from articula.scene import Obstacle, Scene
from tests.planning.helpers import FREE, Q_BENT, ROBOT, ball
from tests.scene.helpers import book_scene


def test_objective_is_tracking_error_plus_inverse_distance_penalty():
    scene = ball([0.4, 0.3, 0.6], 0.1)
    x_ref = np.array([0.3, 0.2, 0.7])
    error = np.linalg.norm(x_ref - ROBOT.ee_position(Q_BENT))
    assert Objective(scene, 0.0).value(Q_BENT, x_ref) == pytest.approx(error)
    d = scene.min_distance(Q_BENT)
    assert Objective(scene, 0.01, 2.0).value(Q_BENT, x_ref) == pytest.approx(error + 0.01 / d**2)


def test_projection_clips_to_limits_and_refuses_points_too_close():
    scene = ball([0.4, 0.3, 0.6], 0.1)
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


def test_a_point_inside_an_obstacle_is_outside_omega_on_both_paths():
    # Ω is d > d_min (Eq. 1.12): with d_min = 0 an overlapping antenna stays at (θ_k, g_k) on
    # the compiled path (clearance 0) as on the coal path (negative signed distance).
    scene = book_scene("circle_two_obstacles")
    rng = np.random.default_rng(11)
    overlapping = next(
        q for q in rng.uniform(ROBOT.lower, ROBOT.upper, (500, ROBOT.nq))
        if scene.min_distance(q) < 0
    )  # fmt: skip
    current, x_ref = np.zeros(ROBOT.nq), np.array([0.2, 0.6, 0.5])
    for compiled in (True, False):
        objective = Objective(scene, 0.005, 1.0, 0.0, use_compiled=compiled)
        assert (objective.compiled is not None) == compiled
        q, g = objective.project_and_value(overlapping, current, 1.25, x_ref, 0.0)
        assert q is current and g == 1.25


def test_a_scene_without_a_compiled_form_is_evaluated_with_coal():
    round_rim = Obstacle("c", (cylinder(0.05, 0.2),), pose([0.3, 0.3, 0.5]))
    scene = Scene(ROBOT, [round_rim])
    objective = Objective(scene, 0.001, 1.0, 0.0)
    assert objective.compiled is None
    q = np.zeros(ROBOT.nq)
    expected = np.linalg.norm(np.array([0.2, 0.6, 0.5]) - ROBOT.ee_position(q)) + 0.001 / (
        scene.min_distance(q)
    )
    assert objective.value(q, np.array([0.2, 0.6, 0.5])) == pytest.approx(expected)


@pytest.mark.parametrize("name", ["lambda_weight", "beta", "d_min"])
@pytest.mark.parametrize("value", [-0.1, np.nan, np.inf])
def test_bad_weights_name_the_objective_field(name, value):
    weights = {"lambda_weight": 0.0, name: value}
    with pytest.raises(ConfigError) as exc:
        Objective(FREE, **weights)
    assert exc.value.field == f"Objective.{name}"
