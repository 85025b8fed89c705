"""planning/config.py: make_planner builds the planner each method names with the spec's
parameters and seed; make_trajectory builds each path type; PlannerSpec's defaults and checks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.planning.baornn import Baornn
from articula.planning.baornn_improved import ImprovedBaornn
from articula.planning.config import PlannerSpec, TrajectorySpec, make_planner, make_trajectory
from articula.planning.qp_ik import QpIk
from articula.planning.trajectories import Circle, Waypoints
from articula.planning.velocity_ik import VelocityIk
from articula.validation import parse_model
from tests.planning.helpers import CIRCLE, ROBOT, ball

SCENE = ball([0.4, 0.3, 0.6], 0.1)
# Values unlike the defaults, so that each one is seen to reach the planner.
BEETLE = {"lambda_weight": 0.004, "beta": 2.0, "d_min": 0.003, "c1": 0.2, "c2": 0.7,
          "iterations_per_step": 4}  # fmt: skip
BASELINE = {"dt": 0.02, "d_min": 0.003, "gain": 12.0, "influence": 0.2, "safety": 0.05,
            "damping": 0.03, "repulsion": 0.01}  # fmt: skip


@pytest.mark.parametrize(
    ("method", "kind"), [("baornn", Baornn), ("baornn-improved", ImprovedBaornn)]
)
def test_make_planner_builds_a_beetle_search_on_the_spec_objective(method, kind):
    improved = {"pairs": 5, "short_antenna": 0.5, "yield_distance": 0.04, "newton_damping": 0.01,
                "quiet_error": 2e-5, "flat_penalty_slope": 0.2,
                "slide_reach": 0.02}  # fmt: skip
    spec = PlannerSpec(method=method, **improved, **BEETLE)
    planner = make_planner(spec, SCENE, seed=0)
    assert type(planner) is kind
    assert planner.scene is SCENE
    objective = planner.objective
    assert (objective.lambda_weight, objective.beta, objective.d_min) == (0.004, 2.0, 0.003)
    params = planner.params
    assert (params.c1, params.c2, params.iterations_per_step) == (0.2, 0.7, 4)
    if method == "baornn-improved":
        # Every field of ImprovedParams is a [planner] key, and each one reaches it.
        assert set(type(params).model_fields) <= set(PlannerSpec.model_fields)
        assert {k: getattr(params, k) for k in improved} == improved


def test_make_planner_builds_the_qp_baseline():
    planner = make_planner(PlannerSpec(method="qp", **BASELINE), SCENE, seed=0)
    assert type(planner) is QpIk
    assert planner.scene is SCENE and planner.dt == 0.02 and planner.d_min == 0.003
    assert (planner.params.gain, planner.params.influence, planner.params.safety) == (
        12.0, 0.2, 0.05,
    )  # fmt: skip


@pytest.mark.parametrize("method", ["pinv", "dls"])
def test_make_planner_builds_the_velocity_baselines(method):
    planner = make_planner(PlannerSpec(method=method, **BASELINE), SCENE, seed=0)
    assert type(planner) is VelocityIk
    assert planner.method == method
    assert planner.scene is SCENE and planner.dt == 0.02 and planner.d_min == 0.003
    p = planner.params
    assert (p.gain, p.damping, p.repulsion, p.influence) == (12.0, 0.03, 0.01, 0.2)


def test_make_planner_draws_all_randomness_from_the_seed():
    spec = PlannerSpec(method="baornn", limits="none", **BEETLE)
    q0, x_ref = np.zeros(ROBOT.nq), CIRCLE(0.0)
    steps = [make_planner(spec, SCENE, seed).step(q0, x_ref, 0.0) for seed in (1, 1, 2)]
    np.testing.assert_array_equal(steps[0], steps[1])
    assert not np.array_equal(steps[0], steps[2])


def test_settle_defaults_to_five_seconds_or_half_the_run():
    assert PlannerSpec().settle == 5.0
    assert PlannerSpec(duration=2.0).settle == 1.0
    assert PlannerSpec(duration=2.0, settle=0.5).settle == 0.5


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"method": "magic"}, "PlannerSpec.method"),
        ({"duration": 2.0, "settle": 2.0}, "PlannerSpec.settle"),
    ],
)
def test_bad_planner_specs_name_the_field(kwargs, field):
    with pytest.raises(ConfigError) as exc:
        PlannerSpec(**kwargs)
    assert exc.value.field == field


def test_make_trajectory_builds_the_circle():
    spec = TrajectorySpec(type="circle", center=[0.0, 0.6, 0.5], axis_a=[1.0, 0.0, 0.0],
                          axis_b=[0.0, 0.0, 1.0], radius=0.2, period=50.0)  # fmt: skip
    path = make_trajectory(spec, Path("."))
    assert isinstance(path, Circle)
    for t in (0.0, 7.3, 12.5):
        np.testing.assert_array_equal(path(t), CIRCLE(t))


def test_make_trajectory_builds_rectangles_and_waypoints():
    vertices = [[0.2, 0.6, 0.8], [-0.1, 0.6, 0.8], [-0.1, 0.6, 0.2], [0.2, 0.6, 0.2]]
    rectangle = make_trajectory(TrajectorySpec(type="rectangle", vertices=vertices, period=50.0),
                                Path("."))  # fmt: skip
    np.testing.assert_allclose(rectangle(50.0 * 0.3 / 1.8), vertices[1])
    points = [[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]
    waypoints = make_trajectory(TrajectorySpec(type="waypoints", points=points, times=[0.0, 2.0]),
                                Path("."))  # fmt: skip
    assert isinstance(waypoints, Waypoints)
    np.testing.assert_allclose(waypoints(1.0), [0.5, 1.0, 1.5])


def test_make_trajectory_reads_a_csv_relative_to_the_base_folder(tmp_path):
    (tmp_path / "path.csv").write_text("t,x,y,z\n0,0,0,0\n1,1,0,0\n")
    path = make_trajectory(TrajectorySpec(type="csv", path="path.csv"), tmp_path)
    np.testing.assert_allclose(path(0.5), [0.5, 0.0, 0.0])


def test_a_trajectory_type_needs_its_fields():
    with pytest.raises(ConfigError, match="center") as exc:
        TrajectorySpec(type="circle")
    assert exc.value.field == "TrajectorySpec"


@pytest.mark.parametrize(
    ("table", "field"),
    [
        ({"type": "circle", "center": [0, 0.6, 0.5], "axis_a": [1, 0, 0], "axis_b": [1, 0, 0],
          "radius": 0.2, "period": 10.0}, "trajectory.axis_b"),
        ({"type": "waypoints", "points": [[0, 0, 0], [1, 0, 0]], "times": [1.0, 1.0]},
         "trajectory.times"),
        ({"type": "csv", "path": "missing.csv"}, "trajectory.path"),
    ],
    ids=["circle_axes", "waypoint_times", "csv_path"],
)  # fmt: skip
def test_make_trajectory_names_the_trajectory_key_at_fault(tmp_path, table, field):
    with pytest.raises(ConfigError) as err:
        make_trajectory(TrajectorySpec(**table), tmp_path)
    assert err.value.field == field


def test_make_planner_names_the_planner_key_of_a_qp_parameter_at_fault():
    spec = PlannerSpec(method="qp", safety=0.2, influence=0.1)  # the table alone is fine
    with pytest.raises(ConfigError) as exc:
        make_planner(spec, ball([0.4, 0.3, 0.6], 0.1), seed=0)
    assert exc.value.field == "planner.safety"


def test_a_run_longer_than_max_steps_is_refused_naming_how_to_raise_it():
    with pytest.raises(ConfigError) as exc:
        PlannerSpec(duration=1e9)
    assert exc.value.field == "PlannerSpec.duration" and "planner.max_steps" in exc.value.problem
    assert PlannerSpec(duration=2e4, max_steps=2_000_000).duration == 2e4


@pytest.mark.parametrize("limits", ["velocity", "none"])
def test_an_acceleration_override_without_acceleration_limits_is_refused(limits):
    table = {"method": "qp", "limits": limits, "max_acceleration": 5.0}
    with pytest.raises(ConfigError, match=r"^scene\.toml: max_acceleration: limits = "):
        parse_model(PlannerSpec, table, "scene.toml")


@pytest.mark.parametrize("method", ["baornn", "baornn-improved", "pinv", "dls", "qp"])
def test_every_method_takes_the_robots_acceleration_limits_or_the_override(method):
    planner = make_planner(PlannerSpec(method=method), SCENE, seed=0)
    rate = planner.rate
    np.testing.assert_allclose(rate.acceleration, ROBOT.acceleration_limit)
    np.testing.assert_allclose(ROBOT.acceleration_limit, ROBOT.velocity_limit / 0.25)
    override = make_planner(PlannerSpec(method=method, max_acceleration=5.0), SCENE, seed=0)
    np.testing.assert_allclose(override.rate.acceleration, 5.0)
    assert make_planner(PlannerSpec(method=method, limits="velocity"), SCENE, 0).rate.change is None
