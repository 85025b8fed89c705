"""Self-collision in the closed loop: a path that folds the iiwa's wrist into its base is
followed into collision with self_collision off, and kept clear of itself with it on, by every
method that keeps clearance as a constraint."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.errors import InfeasibleError
from articula.loops.online import OnlineController
from articula.loops.tracking import track
from articula.planning.config import PlannerSpec, TrajectorySpec, make_planner, make_trajectory
from articula.scene import Scene
from articula.scene.config import build_scene, load_scene_spec
from articula.scene.self_collision import self_collision_matrix

Q0 = [0.0, 0.6, 0.0, -1.2, 0.0, 1.0, 0.0]
FOLDED_TARGET = [0.0, 0.2, 0.1]  # beside the base, below the shoulder: reached by folding


def fold(method: str, self_collision: bool) -> tuple[float, float]:
    """(smallest self clearance over the run [m], final tracking error [m])."""
    robot = {"builtin": "iiwa14", "self_collision": self_collision, "q0": Q0}
    scene, q0 = build_scene(load_scene_spec({"robot": robot}), Path("."))
    start = scene.robot.ee_position(q0).tolist()
    path = TrajectorySpec(type="waypoints", points=[start, FOLDED_TARGET], times=[0.0, 2.0])
    planner = make_planner(PlannerSpec(method=method, duration=4.0), scene, seed=0)
    run = track(planner, make_trajectory(path, Path(".")), q0, 0.01, 4.0)
    # An independent judge: every pair the matrix checks, whatever the planner was told.
    judge = Scene(scene.robot, [], self_pairs=self_collision_matrix(scene.robot).checked)
    return min(judge.self_clearance(q) for q in run.q), float(run.error[-1])


@pytest.mark.slow_cases(keep=("qp",))
@pytest.mark.parametrize("method", ["baornn-improved", "qp"])
def test_self_collision_stops_a_motion_that_folds_the_arm_into_itself(method):
    unchecked, _ = fold(method, self_collision=False)
    assert unchecked < 0.0  # without the check the wrist goes into the base
    checked, error = fold(method, self_collision=True)
    assert checked > 0.0  # by the judge, coal, whatever GJK the planner used
    assert error < 0.02  # and the target is still reached, by another posture


def test_a_start_folded_into_itself_is_refused():
    robot = {"builtin": "iiwa14", "self_collision": True}
    scene, _ = build_scene(load_scene_spec({"robot": robot}), Path("."))
    controller = OnlineController.from_spec(scene, PlannerSpec(method="qp"))
    with pytest.raises(InfeasibleError, match=r"q0.*collides with itself: links iiwa_link_5 and "
                       "iiwa_link_7"):  # fmt: skip
        controller.reset(np.array([0.0, 1.9, 0.0, 2.0, 0.0, 2.0, 0.0]))
