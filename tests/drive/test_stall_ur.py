"""A planner that stalls stops a real-protocol arm: the servo loop, streaming to the fake
controller through ur-rtde, runs out of set-points, plays the stream's braking path and stops
the program; the fake's own log shows the arm at rest within its limits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.arms.servo_loop import ServoLoop
from articula.arms.ur import URArm
from articula.errors import StallError
from articula.experiments.plan import build_plan, load_plan
from articula.loops.servo import ServoLimits, ServoStream
from tests.drive.fake import Fake, joints, realtime_here, scene_file

pytest.importorskip("rtde_control", reason='needs ur-rtde: pip install ".[ur]"')
pytest.importorskip("mujoco", reason='the fake runs the twin: pip install ".[sim]"')

H = 0.002  # [s] the fake's cycle


@pytest.mark.slow
def test_a_stalled_planner_brings_the_arm_to_rest_and_stops_the_program(tmp_path: Path):
    scene = scene_file(tmp_path)
    plan = build_plan(load_plan(scene), scene.parent, str(scene))
    controller = plan.controller()
    fake = Fake(scene, tmp_path)
    arm = URArm(fake.host, 500.0)
    robot, dt = plan.scene.robot, plan.spec.dt
    with realtime_here():  # a busy machine must not starve the stream before the stall
        start = arm.connect()
        stream = ServoStream(ServoLimits.of(robot), dt, arm.rate)
        loop = ServoLoop(arm, stream, robot, start)
        for k in range(60):  # 0.6 s of the approach, then the planner stalls
            loop.push(controller.step(plan.reference(k * dt), q_measured=loop.latest().q))
        loop.ended.wait()
    assert loop.stalled and loop.braked and loop.error is None
    with pytest.raises(StallError, match="behind the stream"):
        loop.push(controller.q)
    arm.close()
    fake.wait_for("program stopped: stopScript")
    log = fake.log()
    qc, q = joints(log, "qc"), joints(log, "q")
    moved = np.max(np.abs(qc - qc[0]), axis=1)
    assert moved.max() > 1e-3  # it was moving
    speed = np.abs(np.diff(q, axis=0)) / H
    assert np.all(speed <= 1.05 * robot.velocity_limit)
    assert np.max(np.abs(np.diff(q[-20:], axis=0))) / H < 1e-3  # at rest
    assert not any("protective stop" in line or "watchdog:" in line for line in fake.lines)
