"""Orientation tasks in the closed loop: a tool axis kept within its cone on a circle, a pose held
along it, and the online controller's pose targets."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.loops.online import OnlineController
from articula.loops.tracking import track, tracking_metrics
from articula.planning.approach import approach
from articula.planning.config import PlannerSpec, TrajectorySpec, make_planner, make_targets
from articula.planning.task import Target
from articula.scene.config import build_scene, load_scene_spec

Q0 = [0.0, 0.4, 0.0, -1.2, 0.0, 0.6, 0.0]
CIRCLE = dict(type="circle", center=[0.0, 0.6, 0.5], axis_a=[1.0, 0.0, 0.0],
              axis_b=[0.0, 0.0, 1.0], radius=0.15, period=10.0)  # fmt: skip
SCENE, START = build_scene(load_scene_spec({"robot": {"builtin": "iiwa14", "q0": Q0}}), Path("."))


def run(method: str, task: str, **trajectory) -> dict[str, float]:
    """Metrics of a 12 s run after an approach from the start to the circle, from 1 s into it."""
    targets = make_targets(TrajectorySpec(**CIRCLE, **trajectory), Path("."))
    planner = make_planner(PlannerSpec(method=method, duration=12.0, task=task), SCENE, seed=0)
    pose = SCENE.robot.ee_pose(START)
    tool = Target(pose[:3, 3], pose[:3, :3].copy(), pose[:3, :3] @ planner.task.tool_axis)
    reference = approach(targets, tool, speed=0.25, turn_rate=0.5)
    result = track(planner, reference, START, 0.01, reference.duration + 12.0,
                   path_start=reference.duration)  # fmt: skip
    return tracking_metrics(result, SCENE.robot, 1.0, planner.iterations, targets.cone)


@pytest.mark.slow_cases(keep=("qp",))
@pytest.mark.parametrize("method", ["baornn-improved", "qp", "dls", "pinv"])
def test_a_pose_task_keeps_the_tool_axis_within_its_cone_on_a_circle(method):
    # The tool (z) axis points 36° below the horizontal at the start; asked to point
    # straight down within 0.1 rad while the end effector runs the circle.
    m = run(method, "position+axis", axis=[0.0, 0.0, -1.0], cone=0.1)
    if method == "baornn-improved":
        # Pointing down there bends the wrist until links 5 and 7 are self_d_min apart, and
        # the beetle search, which only rejects points beyond that boundary, slides along it
        # slowly: a known limit (docs/deviations.md), bounded here.
        assert m["cone_violations"] <= 0.1 * 1200 and m["max_orientation_error"] <= 0.15
    else:
        assert m["cone_violations"] == 0
        assert m["max_orientation_error"] <= 0.1
    assert m["rms_error"] < 0.005
    assert m["max_speed_ratio"] <= 1.0 + 1e-9
    assert m["max_acceleration_ratio"] <= 1.0 + 1e-9
    assert m["min_self_clearance"] >= SCENE.self_d_min - 1e-6


@pytest.mark.slow_cases(keep=("qp-0.0001-0.001",))
@pytest.mark.parametrize(
    ("method", "position", "turn"), [("qp", 1e-4, 1e-3), ("baornn-improved", 5e-3, 0.05)]
)
def test_a_pose_task_holds_the_start_orientation_along_the_circle(method, position, turn):
    m = run(method, "pose")  # no orientation given: the start's is held
    assert m["rms_error"] < position
    assert m["max_orientation_error"] < turn


def test_the_position_task_has_no_orientation_columns():
    m = run("qp", "position")
    assert "rms_orientation_error" not in m


def test_online_steps_take_a_pose_target_and_hold_what_it_lacks():
    spec = PlannerSpec(method="qp", task="pose")
    controller = OnlineController.from_spec(SCENE, spec)
    controller.reset(START)
    held = SCENE.robot.ee_pose(START)
    target = held.copy()
    target[:3, 3] += [0.0, 0.0, -0.005]
    for _ in range(50):
        q = controller.step(target)
    np.testing.assert_allclose(SCENE.robot.ee_pose(q), target, atol=1e-4)
    for _ in range(20):
        q = controller.step(held[:3, 3])  # a position: the start's orientation is held
    np.testing.assert_allclose(SCENE.robot.ee_pose(q), held, atol=1e-4)
