"""robots/model.py on general URDFs: continuous joints without position limits (wrapped), locked
joints (a reduced model), mimic joints and an offset tool point, against the small arm's
hand-written kinematics; every refusal names its field."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from articula.errors import ConfigError
from articula.geometry.poses import pose
from articula.robots import RobotModel
from tests.robots.helpers import rot_y, rot_z, urdf_origin
from tests.robots.test_model import hand_small_ee

CONTINUOUS_J2 = ('name="j2" type="revolute"', 'name="j2" type="continuous"')


def test_continuous_joint_has_no_position_limit_and_wraps_the_shortest_way(build_edited):
    robot = build_edited(*CONTINUOUS_J2)
    assert robot.nq == 3 and robot.model.nv == 3
    assert robot.joint_names == ["j1", "j2", "j3"]
    assert robot.continuous.tolist() == [False, True, False]
    np.testing.assert_allclose(robot.lower, [-3, -np.inf, 0])
    np.testing.assert_allclose(robot.upper, [3, np.inf, 0.2])
    np.testing.assert_allclose(robot.sample_range[0], [-3, -math.pi, 0])
    assert robot.velocity_limit[1] == 1.0  # the URDF's <limit velocity="1"> is kept
    for angle in np.linspace(-2 * math.pi, 2 * math.pi, 9):
        q = np.array([0.4, angle, 0.1])
        np.testing.assert_allclose(robot.ee_position(q), hand_small_ee(q), atol=1e-12)
        wrapped = robot.wrap(q)
        assert -math.pi < wrapped[1] <= math.pi and wrapped[[0, 2]].tolist() == [0.4, 0.1]
        np.testing.assert_allclose(robot.ee_position(wrapped), hand_small_ee(q), atol=1e-12)
    # 3.1 → -3.1 is a turn of 0.083 rad the short way, not 6.2 rad back.
    a, b = np.array([0.0, -3.1, 0.0]), np.array([0.0, 3.1, 0.0])
    np.testing.assert_allclose(robot.difference(a, b), [0.0, 2 * math.pi - 6.2, 0.0])
    np.testing.assert_allclose(robot.difference(a, b)[[0, 2]], (a - b)[[0, 2]])


def test_wrap_turns_a_continuous_joint_by_whole_turns_into_the_half_open_period(build_edited):
    robot = build_edited(*CONTINUOUS_J2)
    angles = st.floats(-1e3, 1e3, allow_nan=False) | st.sampled_from(
        [math.pi, -math.pi, 3 * math.pi, math.nextafter(math.pi, 4), math.nextafter(-math.pi, -4)]
    )

    # No wall-clock limits: the machine is shared.
    @settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.lists(angles, min_size=3, max_size=3))
    def wraps(values: list[float]) -> None:
        q = np.array(values)
        wrapped = robot.wrap(q)
        assert -math.pi < wrapped[1] <= math.pi
        turns = (q[1] - wrapped[1]) / (2 * math.pi)
        assert abs(turns - round(turns)) < 1e-12 * max(1.0, abs(q[1]))
        assert wrapped[[0, 2]].tolist() == q[[0, 2]].tolist()  # not continuous: untouched

    wraps()


def test_continuous_joint_without_limit_element_has_no_speed_limit(build_edited):
    robot = build_edited(
        'name="j2" type="revolute">\n    <parent link="link1"/><child link="link2"/>\n'
        '    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>\n'
        '    <limit lower="-2" upper="2" effort="1" velocity="1"/>',
        'name="j2" type="continuous">\n    <parent link="link1"/><child link="link2"/>\n'
        '    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>',
    )
    np.testing.assert_allclose(robot.upper, [3, np.inf, 0.2])
    assert robot.velocity_limit[1] == np.inf
    assert robot.acceleration_limit[1] == np.inf  # no speed limit: no acceleration from it
    assert robot.model.effortLimit[1] == np.inf
    q = (0.2, -5.0, 0.0)
    np.testing.assert_allclose(robot.ee_position(q), hand_small_ee(q), atol=1e-12)


@pytest.mark.parametrize("value", [-1.2, 0.0, 0.7])
def test_locked_joint_shows_in_forward_kinematics_and_leaves_q(small_arm, value):
    robot = RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], locked_joints={"j2": value})
    assert robot.nq == 2
    assert robot.joint_names == ["j1", "j3"]
    np.testing.assert_allclose(robot.lower, [-3, 0])
    np.testing.assert_allclose(robot.upper, [3, 0.2])
    for q1, q3 in [(0.0, 0.0), (0.5, 0.1), (-2.0, 0.2)]:
        np.testing.assert_allclose(
            robot.ee_position((q1, q3)), hand_small_ee((q1, value, q3)), atol=1e-12
        )
    # Every link keeps its collision shapes and its placement on the locked joint's parent.
    assert [link.name for link in robot.links] == ["base", "link1", "link2", "link3"]
    poses = robot.link_poses((0.5, 0.1))
    np.testing.assert_allclose(poses["link2"][:3, :3], rot_z(0.5) @ rot_y(value), atol=1e-12)


def test_locked_prismatic_joint_and_the_jacobian_of_the_reduced_model(small_arm):
    robot = RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], locked_joints={"j3": 0.15})
    q = np.array([0.3, -0.4])
    np.testing.assert_allclose(robot.ee_position(q), hand_small_ee((0.3, -0.4, 0.15)), atol=1e-12)
    h = 1e-6
    for i in range(2):
        step = np.eye(2)[i] * h
        column = (robot.ee_position(q + step) - robot.ee_position(q - step)) / (2 * h)
        np.testing.assert_allclose(robot.jacobian(q)[:3, i], column, atol=1e-8)


def test_locked_continuous_joint_takes_values_within_two_pi(build_edited, small_arm):
    build_edited(*CONTINUOUS_J2)
    robot = RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], locked_joints={"j2": 6.0})
    np.testing.assert_allclose(robot.ee_position((0.1, 0.0)), hand_small_ee((0.1, 6.0, 0.0)))
    with pytest.raises(ConfigError) as err:
        RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], locked_joints={"j2": 6.5})
    assert err.value.field == "locked_joints.j2"


@pytest.mark.parametrize(
    ("locked", "field", "words"),
    [
        ({"elbow": 0.0}, "locked_joints.elbow", "no joint 'elbow'"),
        ({"j2": 2.5}, "locked_joints.j2", "outside the joint's limits [-2, 2]"),
        ({"j3": -0.1}, "locked_joints.j3", "outside"),
        ({"j1": 0.0, "j2": 0.0, "j3": 0.0}, "locked_joints", "every joint"),
    ],
)
def test_locked_joint_errors_name_the_field(small_arm, locked, field, words):
    with pytest.raises(ConfigError) as err:
        RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], locked_joints=locked)
    assert err.value.field == field
    assert words in err.value.problem


# Two fingers on a revolute base: finger2 mimics finger1 (2·q + 0.01, opposite axis).
FINGERS_URDF = """<?xml version="1.0"?>
<robot name="hand">
  <link name="base"/>
  <joint name="turn" type="revolute">
    <parent link="base"/><child link="palm"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <link name="palm"/>
  <joint name="finger1" type="prismatic">
    <parent link="palm"/><child link="left"/><origin xyz="0.1 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="1" velocity="1"/>
  </joint>
  <link name="left"><collision><geometry><sphere radius="0.01"/></geometry></collision></link>
  <joint name="finger2" type="prismatic">
    <parent link="palm"/><child link="right"/><origin xyz="0.1 0 0"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/>
    <mimic joint="finger1" multiplier="2" offset="0.01"/>
  </joint>
  <link name="right"><collision><geometry><sphere radius="0.01"/></geometry></collision></link>
</robot>
"""


def _hand_right(turn: float, finger1: float) -> np.ndarray:
    return rot_z(turn) @ [0.1, -(2 * finger1 + 0.01), 0.0] + [0.0, 0.0, 0.1]


@pytest.fixture
def fingers(tmp_path):
    path = tmp_path / "hand.urdf"
    path.write_text(FINGERS_URDF)
    return path


def test_mimic_joint_follows_its_joint_and_has_no_entry_in_q(fingers):
    robot = RobotModel.from_urdf(fingers, ee_frame="right")
    assert robot.nq == 2 and robot.model.nv == 2
    assert robot.joint_names == ["turn", "finger1"]
    for q in [(0.0, 0.0), (0.7, 0.03), (-2.0, 0.04)]:
        np.testing.assert_allclose(robot.ee_position(q), _hand_right(*q), atol=1e-12)
    q = np.array([0.7, 0.03])
    h = 1e-6
    step = np.array([0.0, h])
    column = (robot.ee_position(q + step) - robot.ee_position(q - step)) / (2 * h)
    np.testing.assert_allclose(robot.jacobian(q)[:3, 1], column, atol=1e-8)
    assert robot.jacobian(q).shape == (6, 2)


def test_locking_a_mimicked_joint_locks_its_mimic_joint(fingers):
    robot = RobotModel.from_urdf(fingers, ee_frame="right", locked_joints={"finger1": 0.02})
    assert robot.nq == 1 and robot.joint_names == ["turn"]
    np.testing.assert_allclose(robot.ee_position([0.5]), _hand_right(0.5, 0.02), atol=1e-12)
    other = RobotModel.from_urdf(fingers, ee_frame="right", locked_joints={"turn": 0.5})
    np.testing.assert_allclose(other.ee_position([0.02]), _hand_right(0.5, 0.02), atol=1e-12)


def test_a_mimic_joint_cannot_be_locked_by_itself(fingers):
    with pytest.raises(ConfigError) as err:
        RobotModel.from_urdf(fingers, locked_joints={"finger2": 0.05})
    assert err.value.field == "locked_joints.finger2"
    assert "lock 'finger1' instead" in err.value.problem


@pytest.mark.parametrize("ee_frame", [None, "link2"])
def test_ee_offset_point_is_the_frame_pose_times_the_offset(small_arm, ee_frame):
    plain = RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], ee_frame=ee_frame)
    offset = urdf_origin((0.05, -0.02, 0.1), (0.3, -0.2, 1.1))
    robot = RobotModel.from_urdf(
        small_arm["urdf"], [small_arm["pkg"]], ee_frame=ee_frame, ee_offset=offset
    )
    assert robot.ee_frame == f"{plain.ee_frame}_offset"
    assert robot.model.frames[robot.ee_frame_id].name == robot.ee_frame
    for q in [(0.0, 0.0, 0.0), (0.4, -0.9, 0.05), (-2.5, 1.7, 0.2)]:
        np.testing.assert_allclose(robot.ee_pose(q), plain.ee_pose(q) @ offset, atol=1e-12)
    # The Jacobian is that of the tool point: finite differences of its position.
    q = np.array([0.4, -0.9, 0.05])
    h = 1e-6
    for i in range(3):
        step = np.eye(3)[i] * h
        column = (robot.ee_position(q + step) - robot.ee_position(q - step)) / (2 * h)
        np.testing.assert_allclose(robot.jacobian(q)[:3, i], column, atol=1e-8)


def test_ee_offset_with_locked_joints_and_the_built_in_robot():
    offset = pose((0.0, 0.0, 0.12), (0.0, 0.0, 0.5))
    plain = RobotModel.builtin("iiwa14", locked_joints={"iiwa_joint_7": 0.3})
    robot = RobotModel.builtin("iiwa14", locked_joints={"iiwa_joint_7": 0.3}, ee_offset=offset)
    assert robot.nq == 6 and robot.ee_frame == "iiwa_link_ee_offset"
    q = np.array([0.1, 0.5, -0.2, -1.0, 0.3, 0.8])
    np.testing.assert_allclose(robot.ee_pose(q), plain.ee_pose(q) @ offset, atol=1e-12)
    full = RobotModel.builtin("iiwa14")
    np.testing.assert_allclose(robot.ee_pose(q), full.ee_pose([*q, 0.3]) @ offset, atol=1e-12)


@pytest.mark.parametrize(
    ("offset", "field"),
    [(np.eye(3), "ee_offset"), (np.diag([2.0, 1.0, 1.0, 1.0]), "ee_offset")],
)
def test_ee_offset_errors_name_the_field(small_arm, offset, field):
    with pytest.raises(ConfigError) as err:
        RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], ee_offset=offset)
    assert err.value.field == field


def test_ee_offset_on_an_unknown_frame_names_ee_frame(small_arm):
    with pytest.raises(ConfigError) as err:
        RobotModel.from_urdf(
            small_arm["urdf"], [small_arm["pkg"]], ee_frame="gripper", ee_offset=np.eye(4)
        )
    assert err.value.field == "ee_frame"


def test_a_continuous_joint_turns_through_pi_the_short_way(build_edited):
    """From 3.1 rad to a tool position that needs 3.3 rad (−2.98 wrapped): the commands pass
    through π a little at a time, wrapped, within the joint's speed limit."""
    from articula.loops.online import OnlineController
    from articula.planning.config import PlannerSpec
    from articula.scene import Scene

    robot = build_edited(*CONTINUOUS_J2)
    start = np.array([0.4, 3.1, 0.1])
    goal = robot.ee_position(np.array([0.4, 3.3, 0.1]))
    controller = OnlineController.from_spec(Scene(robot, []), PlannerSpec(method="qp", dt=0.01))
    q = [controller.reset(start)]
    for _ in range(300):
        q.append(controller.step(goal))
    q = np.array(q)
    assert np.all(np.abs(q[:, 1]) <= math.pi)  # wrapped
    assert q[-1, 1] == pytest.approx(3.3 - 2 * math.pi, abs=1e-3)  # there, the short way
    motion = robot.difference(q[1:], q[:-1])
    assert np.abs(motion[:, 1]).max() <= robot.velocity_limit[1] * 0.01 * (1 + 1e-9)
    assert np.abs(motion[:, 1]).sum() < 1.0  # not the long way round, 2π − 0.2 rad
