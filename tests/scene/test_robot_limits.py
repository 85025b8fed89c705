"""The [robot] table's limits: acceleration limits (stated, or from the speed limits and
accel_time), self-collision on by default with self_d_min, and their refusals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.experiments.plan import PlanConfig, run_plan
from articula.loops.online import OnlineController
from articula.planning.config import PlannerSpec
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import parse_model


def scene(**robot):
    return build_scene(load_scene_spec({"robot": {"builtin": "iiwa14", **robot}}), Path("."))


def test_acceleration_limits_come_from_the_speeds_over_accel_time_unless_stated():
    default, _ = scene()
    speeds = default.robot.velocity_limit
    np.testing.assert_allclose(default.robot.acceleration_limit, speeds / 0.25)
    slow, _ = scene(accel_time=0.5)
    np.testing.assert_allclose(slow.robot.acceleration_limit, speeds / 0.5)
    one, _ = scene(acceleration_limits=7.5)
    np.testing.assert_allclose(one.robot.acceleration_limit, 7.5)
    each = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
    np.testing.assert_allclose(scene(acceleration_limits=each)[0].robot.acceleration_limit, each)


@pytest.mark.parametrize(
    ("robot", "field"),
    [({"acceleration_limits": [1.0, 2.0]}, "robot.acceleration_limits"),
     ({"acceleration_limits": -1.0}, "robot.acceleration_limits"),
     ({"accel_time": 0.0}, "robot.accel_time"),
     ({"self_d_min": -0.001}, "robot.self_d_min")],
)  # fmt: skip
def test_bad_robot_limits_name_their_key(robot, field):
    with pytest.raises(ConfigError) as err:
        scene(**robot)
    assert err.value.field.endswith(field)


def test_self_collision_is_on_by_default_with_its_minimum_distance():
    on, _ = scene()
    assert on.self_pairs and on.self_d_min == 0.005
    off, _ = scene(self_collision=False, self_d_min=0.01)
    assert not off.self_pairs and off.self_d_min == 0.01


def test_a_start_within_self_d_min_is_refused_naming_the_pair_and_the_key():
    folded, _ = scene()
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.8, 0.0])  # joint 6 bent toward link 5: 10 mm
    gap = folded.self_clearance(q)
    assert 0.0 < gap < 0.05
    tight, _ = scene(self_d_min=float(gap) + 0.001)
    controller = OnlineController.from_spec(tight, PlannerSpec(method="qp"))
    with pytest.raises(InfeasibleError) as err:
        controller.reset(q)
    assert err.value.field == "q0" and "robot.self_d_min" in err.value.problem
    OnlineController.from_spec(folded, PlannerSpec(method="qp")).reset(q)  # 5 mm: accepted


def test_a_pose_task_off_its_orientation_is_not_tracked():
    """A tool turned by 1 rad from the target's orientation, with the orientation's weight
    0: the position is tracked, the orientation not, and the run says so."""
    data = {"robot": {"builtin": "iiwa14", "q0": [0.0, 0.5, 0.0, -1.0, 0.0, 0.6, 0.0]},
            "trajectory": {"type": "waypoints", "points": [[0.45, 0.0, 0.9], [0.45, 0.0, 0.9]],
                           "times": [0.0, 1.0], "rpy": [1.0, 0.0, 0.0]},
            "planner": {"method": "baornn-improved", "task": "pose", "orientation_weight": 0.0,
                        "duration": 2.0, "settle": 1.0}}  # fmt: skip
    result = run_plan(parse_model(PlanConfig, data))
    assert result.metrics["tracked"] is False
    assert "planner.orientation_tolerance" in result.details["not_tracked"]
    data["planner"]["orientation_tolerance"] = 3.0
    result = run_plan(parse_model(PlanConfig, data))  # within the tolerance it is given
    assert result.metrics["tracked"] is True
