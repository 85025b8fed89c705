"""A pipelined loop (the planner periods ahead of the arm, arms.ServoLoop) measures the arm
answering an older period's target: step(lag=) compares the measurement with that target, so
the lead correction does not take the pipeline's delay for the servo's lag."""

from __future__ import annotations

from collections import deque

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.loops.online import MAX_LAG, OnlineController
from articula.planning.approach import approach
from articula.planning.config import PlannerSpec, TrajectorySpec, make_targets
from articula.planning.task import Target
from tests.loops.test_feedback import DATA, DT, LAG, PATH, Q0, ROBOT, SCENE

DELAY = 3  # [periods] the pipeline: a command reaches the servo this many periods late


def _pipelined_rms(lag: int) -> float:
    """The settled RMS error of the measured tool, commands delayed DELAY periods."""
    spec = PlannerSpec(**{**DATA["planner"], "method": "qp", "dt": DT})
    targets = make_targets(TrajectorySpec(**DATA["trajectory"]), PATH.parent)
    controller = OnlineController.from_spec(SCENE, spec, seed=0)
    measured = controller.reset(Q0)
    pose = ROBOT.ee_pose(Q0)
    reference = approach(targets, Target(pose[:3, 3], pose[:3, :3].copy()), 0.25, 0.5)
    queue, errors = deque([Q0.copy()] * DELAY), []
    for k in range(round((reference.duration + 10.0) / DT)):
        queue.append(controller.step(reference(k * DT), q_measured=measured, lag=lag))
        measured = measured + DT / LAG * (queue.popleft() - measured)
        if k * DT >= reference.duration + 5.0:  # settled; the servo is now at period k - DELAY
            errors.append(
                np.linalg.norm(ROBOT.ee_position(measured) - reference((k - DELAY) * DT).position)
            )
    return float(np.sqrt(np.mean(np.square(errors))))


def test_the_measurement_compared_with_the_target_it_answers_tracks_closer():
    assert _pipelined_rms(DELAY) < 0.5 * _pipelined_rms(0)


@pytest.mark.parametrize("lag", [-1, MAX_LAG + 1])
def test_a_lag_outside_its_range_is_refused(lag):
    controller = OnlineController.from_spec(SCENE, PlannerSpec(method="qp", dt=DT))
    controller.reset(Q0)
    with pytest.raises(ConfigError, match="lag"):
        controller.step(ROBOT.ee_position(Q0), q_measured=Q0, lag=lag)
