"""The online controller closed on measured joints: a first-order lagging servo driven by it
brings the measured tool onto the path, while the commands form one stream within the speed
and acceleration limits (and the servo's motion too); a start on a moving arm takes its
velocity."""

from __future__ import annotations

import numpy as np
import pytest

from articula.book.study import packaged
from articula.errors import ConfigError
from articula.loops.online import OnlineController
from articula.planning.approach import approach
from articula.planning.config import PlannerSpec, TrajectorySpec, make_targets
from articula.planning.task import Target
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

PATH = packaged("ch1", "circle_one_obstacle.toml")
DATA = load_toml(PATH)
SCENE, Q0 = build_scene(load_scene_spec(DATA), PATH.parent)
ROBOT = SCENE.robot
DT = 0.01
LAG = 0.05  # [s] the servo's time constant: it covers dt / LAG of the way each period


def _servo_run(method: str, seconds: float, measure: bool = True) -> dict[str, np.ndarray]:
    """The controller driving a first-order servo, fed back by its measured joints (unless
    not `measure`): commands, measured joints, measured tool errors, path start."""
    spec = PlannerSpec(**{**DATA["planner"], "method": method, "dt": DT})
    targets = make_targets(TrajectorySpec(**DATA["trajectory"]), PATH.parent)
    controller = OnlineController.from_spec(SCENE, spec, seed=0)
    measured = controller.reset(Q0)
    pose = ROBOT.ee_pose(Q0)
    reference = approach(targets, Target(pose[:3, 3], pose[:3, :3].copy()), 0.25, 0.5)
    commands, joints, errors = [], [measured.copy()], []
    for k in range(round((reference.duration + seconds) / DT)):
        target = reference(k * DT)
        command = controller.step(target, q_measured=measured if measure else None)
        measured = measured + DT / LAG * (command - measured)  # the servo's first-order lag
        commands.append(command)
        joints.append(measured.copy())
        errors.append(np.linalg.norm(ROBOT.ee_position(measured) - target.position))
    return {"commands": np.array(commands), "measured": np.array(joints),
            "errors": np.array(errors), "path_start": reference.duration}  # fmt: skip


def _within_limits(q: np.ndarray) -> None:
    """Speeds and accelerations of a joint stream from rest, by differences, within limits."""
    motion = np.diff(np.vstack([q[:1], q]), axis=0)
    assert np.all(np.abs(motion) <= ROBOT.velocity_limit * DT * (1 + 1e-9))
    assert np.all(np.abs(np.diff(motion, axis=0)) <= ROBOT.acceleration_limit * DT**2 * (1 + 1e-9))


@pytest.mark.slow_cases(keep=("qp",))
@pytest.mark.parametrize("method", ["qp", "baornn-improved"])
def test_a_lagging_servo_is_brought_onto_the_path_within_every_limit(method):
    run = _servo_run(method, 10.0)
    _within_limits(np.vstack([Q0, run["commands"]]))  # what the arm's controller receives
    _within_limits(run["measured"])  # and how the arm moves
    errors = run["errors"]
    settled = np.arange(len(errors)) * DT >= run["path_start"] + 5.0
    # Without the correction the servo's lag, about v·τ, stays in the measured tool's error.
    assert np.sqrt(np.mean(errors[settled] ** 2)) < 0.5e-3  # [m]
    assert min(SCENE.clearances(x)[0] for x in run["measured"][::10]) > 0.002  # d_min


def test_without_the_measurement_the_lag_stays_in_the_error():
    lagging = _servo_run("qp", 10.0, measure=False)
    corrected = _servo_run("qp", 10.0)
    settled = np.arange(len(lagging["errors"])) * DT >= lagging["path_start"] + 5.0
    rms = {name: np.sqrt(np.mean(r["errors"][settled] ** 2))
           for name, r in (("lagging", lagging), ("corrected", corrected))}  # fmt: skip
    speed = 2 * np.pi * 0.2 / 50.0  # [m/s] the book circle's: the lag is about speed · LAG
    assert rms["lagging"] > 0.5 * speed * LAG > 5 * rms["corrected"]


def test_a_start_on_a_moving_arm_takes_its_velocity():
    spec = PlannerSpec(method="qp", dt=DT)
    controller = OnlineController.from_spec(SCENE, spec)
    velocity = np.full(ROBOT.nq, 0.5)  # [rad/s]
    start = controller.reset(Q0, velocity=velocity)
    q = controller.step(ROBOT.ee_position(Q0))  # asked to hold the tool still
    change = ROBOT.acceleration_limit * DT**2
    # It cannot stop at once: the first motion stays within one period's change of 0.5 rad/s.
    assert np.all(np.abs((q - start) - velocity * DT) <= change * (1 + 1e-9))


def test_a_measured_configuration_of_the_wrong_size_names_the_argument():
    controller = OnlineController.from_spec(SCENE, PlannerSpec(method="qp"))
    controller.reset(Q0)
    with pytest.raises(ConfigError) as err:
        controller.step(ROBOT.ee_position(Q0), q_measured=np.zeros(3))
    assert err.value.field == "q_measured"


def test_a_reset_forgets_the_last_target_and_its_lead():
    controller = OnlineController.from_spec(SCENE, PlannerSpec(method="qp", dt=DT))
    controller.reset(Q0)
    far = ROBOT.ee_position(Q0) + np.array([0.0, 0.0, -0.2])
    for _ in range(20):  # a target the arm lags, measured where it started
        controller.step(far, q_measured=Q0)
    assert np.linalg.norm(controller.lead) > 0
    controller.reset(Q0)
    assert controller.target is None and not controller.lead.any()
    controller.step(ROBOT.ee_position(Q0), q_measured=Q0)  # no error against the old target
    assert not controller.lead.any()


def test_an_arm_that_follows_its_commands_gets_no_lead_where_the_planner_leaves_the_path():
    # The rock's centre as the target: the planner keeps the tool d_min off it, by choice. An
    # arm measured exactly where it was sent does not lag, so nothing is to be made up for:
    # integrating that chosen error (target − measured) wound the lead up against the planner.
    controller = OnlineController.from_spec(SCENE, PlannerSpec(method="qp", dt=DT))
    measured = controller.reset(Q0)
    rock = SCENE.obstacles[0].pose_at(0.0)[:3, 3]
    for _ in range(200):
        measured = controller.step(rock, q_measured=measured)
    assert np.linalg.norm(ROBOT.ee_position(measured) - rock) > 0.01  # kept off by choice
    np.testing.assert_allclose(controller.lead, 0.0, atol=1e-12)
