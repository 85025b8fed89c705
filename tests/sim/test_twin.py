"""sim/twin.py: the MuJoCo twin is the arm articula plans for (kinematics checked against
Pinocchio), its servos follow a jerk-limited stream within their effort limits, and its own
contact detection sees the arm reach an obstacle."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from articula.book.study import packaged
from articula.experiments.plan import build_plan
from articula.loops.servo import run_stream
from articula.loops.tracking import track
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"')
from articula.sim.twin import Twin

CIRCLE = packaged("ch1", "circle_two_obstacles.toml")


@pytest.fixture(scope="module")
def scene():
    return build_scene(load_scene_spec(load_toml(CIRCLE)), CIRCLE.parent)[0]


def test_the_twin_has_the_planned_arms_kinematics(scene):
    twin = Twin(scene, 1000)
    model = scene.robot.model
    data = model.createData()
    for q in np.random.default_rng(0).uniform(-1.5, 1.5, size=(20, 7)):
        twin.reset(q)
        pin.forwardKinematics(model, data, q)
        for j in range(1, model.njoints):
            np.testing.assert_allclose(twin.data.xpos[j], data.oMi[j].translation, atol=1e-12)
            np.testing.assert_allclose(
                twin.data.xmat[j].reshape(3, 3), data.oMi[j].rotation, atol=1e-12
            )


def test_the_servos_hold_a_stretched_arm_against_gravity(scene):
    twin = Twin(scene, 1000)
    q = np.array([0.0, 1.2, 0.0, -0.3, 0.0, 0.5, 0.0])  # reaching out: gravity pulls it down
    twin.reset(q)
    for _ in range(2000):
        twin.step(q, np.zeros(7))
    assert np.max(np.abs(twin.q - q)) < 1e-6
    assert np.abs(twin.torque[1]) > 1.0  # joint 2 carries the arm
    assert twin.contacts() == 0


@pytest.fixture(scope="module")
def followed():
    """qp's plan of the two-obstacle circle (jerk limits, 10 s of path) streamed at 1 kHz
    through the twin: (plan, stream, measured joints, torques, contacts per tick)."""
    data = load_toml(CIRCLE)
    data["planner"].update(method="qp", limits="velocity+acceleration+jerk")
    plan = build_plan(data, CIRCLE.parent, str(CIRCLE))
    p = plan.spec
    lead = plan.reference.duration
    run = track(plan.planner(), plan.reference, plan.q0, p.dt, lead + 10.0, p.max_steps, None, lead)
    stream, _ = run_stream(run, plan.scene.robot, 1000)
    twin = Twin(plan.scene, 1000)
    twin.reset(stream.q[0])
    measured, torque, contacts = [], [], []
    for k in range(1, len(stream.q)):
        twin.step(stream.q[k], stream.qd[k])
        measured.append(twin.q)
        torque.append(twin.torque)
        contacts.append(twin.contacts())
    return plan, stream, np.array(measured), np.array(torque), np.array(contacts), twin


def test_the_twin_follows_the_stream_within_its_effort_limits(followed):
    plan, stream, measured, torque, contacts, twin = followed
    robot = plan.scene.robot
    tool = np.array([robot.ee_position(q) for q in measured[::10]])
    commanded = np.array([robot.ee_position(q) for q in stream.q[1::10]])
    error = np.linalg.norm(tool - commanded, axis=1)
    assert np.sqrt(np.mean(error**2)) < 0.5e-3  # [m]
    assert np.all(np.abs(torque) <= twin.effort * (1 + 1e-9))
    assert contacts.max() == 0


def test_the_measured_motion_keeps_clear_of_the_obstacles_by_coal(followed):
    """The measured joints' clearance, by coal on the scene's shapes (not the planner's
    compiled GJK), stays above the plan's d_min."""
    plan, _, measured, _, _, _ = followed
    clearance = [plan.scene.clearances(q)[0] for q in measured[::20]]
    assert min(clearance) > plan.config.planner.d_min


def test_mujoco_sees_the_arm_reach_an_obstacle(scene):
    """Joint 1 swung toward the bracket until the arm touches it: MuJoCo counts
    contacts once coal's clearance has fallen to zero."""
    twin = Twin(scene, 1000)
    q = np.array([0.0, 0.9, 0.0, -0.6, 0.0, 0.6, 0.0])
    twin.reset(q)
    touched, clear_before = None, []
    for k in range(6000):
        target = q.copy()
        target[0] = 1.5 * min(1.0, k / 5000)
        twin.step(target, np.zeros(7))
        if twin.contacts():
            touched = twin.q
            break
        clear_before.append(scene.clearances(twin.q)[0])
    assert touched is not None, "the arm never reached an obstacle"
    assert scene.clearances(touched)[0] < 2e-3 and min(clear_before) > -2e-3
