"""loops/online.py: the controller a live loop calls every period, and what track shares."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.geometry.poses import pose
from articula.loops.online import OnlineController
from articula.loops.tracking import track
from articula.planning.config import PlannerSpec, make_planner
from tests.planning.helpers import CIRCLE, DT, ROBOT, ball

SPEC = PlannerSpec(method="qp", d_min=0.002, duration=1.0, settle=0.5)
Q0 = np.zeros(ROBOT.nq)


def test_a_loop_of_steps_gives_the_trajectory_of_track():
    scene = ball([0.4, 0.3, 0.6], 0.05)
    run = track(make_planner(SPEC, scene, 0), CIRCLE, Q0, DT, 0.3)
    controller = OnlineController.from_spec(scene, SPEC)
    controller.reset(Q0)
    steps = [controller.step(CIRCLE(n * DT)) for n in range(len(run.t))]
    np.testing.assert_array_equal(np.array(steps), run.q)
    assert controller.t == pytest.approx(0.3)


def test_reset_refuses_a_start_in_collision_or_within_d_min_naming_q0():
    controller = OnlineController.from_spec(ball([0.0, 0.0, 0.8], 0.3), SPEC)
    with pytest.raises(InfeasibleError) as err:
        controller.reset(Q0)
    assert err.value.field == "q0" and "collides" in err.value.problem


def test_a_live_obstacle_moved_into_the_arm_is_kept_out_by_the_qp():
    controller = OnlineController.from_spec(ball([0.8, 0.8, 0.1], 0.05), SPEC, live_obstacles=True)
    q = controller.reset(Q0)
    scene = controller.planner.scene
    far = scene.min_distance(q)
    for n in range(150):
        # The ball comes down onto the stretched arm's upper links at 0.25 m/s.
        q = controller.step([0.0, 0.0, 1.306], {"ball": pose([0.1, 0.0, 1.6 - 0.0025 * n])})
        assert scene.min_distance(q, controller.t) > SPEC.d_min
    assert scene.min_distance(q, controller.t) < far  # the obstacle really came close


def test_step_before_reset_and_unknown_or_bad_obstacles_are_config_errors():
    controller = OnlineController.from_spec(ball([0.8, 0.8, 0.1], 0.05), SPEC, live_obstacles=True)
    with pytest.raises(ConfigError, match="reset"):
        controller.step([0.0, 0.6, 0.5])
    controller.reset(Q0)
    with pytest.raises(ConfigError) as err:
        controller.step([0.0, 0.6, 0.5], {"box": np.eye(4)})
    assert err.value.field == "obstacle_poses"
    with pytest.raises(ConfigError) as err:
        controller.step([0.0, 0.6, 0.5], {"ball": np.full((4, 4), np.nan)})
    assert err.value.field == "obstacle_poses.ball"
    with pytest.raises(ConfigError) as err:
        controller.step([0.0, np.nan, 0.5])
    assert err.value.field == "target"


def test_obstacles_are_not_live_unless_asked():
    controller = OnlineController.from_spec(ball([0.8, 0.8, 0.1], 0.05), SPEC)
    controller.reset(Q0)
    with pytest.raises(ConfigError, match="live_obstacles"):
        controller.step([0.0, 0.6, 0.5], {"ball": np.eye(4)})
