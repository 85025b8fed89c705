"""The servo loop on the MuJoCo twin as an Arm: the planner's set-points streamed at the
servo rate and measured back, the braking path at the end, a stalled planner stopping the arm."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.errors import StallError
from articula.experiments.plan import build_plan
from articula.loops.online import OnlineController
from articula.loops.servo import ServoLimits, ServoStream
from tests.arms import arm_scene

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"')

from articula.arms.servo_loop import ServoLoop
from articula.arms.twin import TwinServo

RATE = 500.0


@pytest.fixture(scope="module")
def plan():
    return build_plan(arm_scene("ur10", 3.0), Path.cwd())


def _loop(plan) -> tuple[ServoLoop, TwinServo, OnlineController]:
    arm = TwinServo(plan.scene, plan.q0, RATE)
    start = arm.connect()
    dt = plan.config.planner.dt
    stream = ServoStream(ServoLimits.of(plan.scene.robot), dt, RATE)
    controller = OnlineController.from_spec(plan.scene, plan.config.planner)
    controller.reset(start.q)
    return ServoLoop(arm, stream, plan.scene.robot, start), arm, controller


def test_the_measured_arm_follows_the_stream_and_ends_at_rest(plan):
    loop, arm, controller = _loop(plan)
    dt, periods = plan.config.planner.dt, 60
    for k in range(periods):
        q = controller.step(plan.reference(k * dt), q_measured=loop.latest().q)
        loop.push(q)
    loop.finish()
    assert loop.braked and not loop.stalled
    ticks = loop.stream.ticks
    assert len(loop.sent) >= periods * ticks  # every set-point's ticks, then the braking path
    sent, measured = np.array(loop.sent), np.array([m.q for m in loop.measured[1:]])
    assert np.max(np.abs(sent - measured)) < 0.01  # [rad] the twin's servos follow
    assert np.max(np.abs(arm.twin.data.qvel)) < 1e-3  # [rad/s] at rest
    assert loop.pacer.latency().releases == len(loop.sent)


def test_a_stalled_planner_brings_the_arm_to_rest_and_the_next_push_says_so(plan):
    loop, arm, controller = _loop(plan)
    dt = plan.config.planner.dt
    for k in range(20):
        loop.push(controller.step(plan.reference(k * dt), q_measured=loop.latest().q))
    loop.ended.wait()  # no further set-point: the stream runs dry
    assert loop.stalled and loop.braked
    assert np.max(np.abs(arm.twin.data.qvel)) < 1e-3
    with pytest.raises(StallError, match="behind the stream"):
        loop.push(controller.q)
