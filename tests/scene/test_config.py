"""scene/config.py: a scene file's robot and obstacles, moving ones included (a `velocity` moves
an obstacle at constant speed), give the distances written out by hand."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml
from tests.scene.helpers import box_signed_distance

BALL_URDF = """<?xml version="1.0"?>
<robot name="ball">
  <link name="base"/>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="ball"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="ball">
    <collision><origin xyz="0.1 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="ball"/><child link="tool"/>
    <origin xyz="0 0.2 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <link name="tool">
    <collision><origin xyz="0.1 0 0"/><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
</robot>
"""


def test_moving_sphere_from_toml(tmp_path, write_toml):
    (tmp_path / "ball.urdf").write_text(BALL_URDF)
    path = write_toml(
        {
            "robot": {"urdf": "ball.urdf", "q0": [0.05]},
            "obstacles": [
                {
                    "name": "comet",
                    "sphere": 0.1,
                    "position": [1.0, 0.0, 0.0],
                    "velocity": [-0.2, 0.0, 0.0],
                },
                {"name": "rock", "sphere": 0.1, "position": [1.0, 0.0, 0.0]},
                {
                    "name": "crate",
                    "box": [0.2, 0.3, 0.2],
                    "position": [0.1, -1.0, 0.1],
                    "rpy": [0.0, 0.0, 0.5],
                    "velocity": [0.0, 0.25, 0.0],
                },
            ],
        },
        "scene.toml",
    )
    scene, q0 = build_scene(load_scene_spec(load_toml(path)), tmp_path)
    np.testing.assert_array_equal(q0, [0.05])
    assert scene.link_names == ["ball", "tool"]
    assert [o.moving for o in scene.obstacles] == [True, False, True]
    for q in (0.0, 0.05, -0.3):
        for t in (0.0, 1.0, 2.5, 4.5, 5.0, 7.0):
            x = 1.0 - 0.2 * t  # the comet's centre moves along x
            expected_ball = math.dist((x, 0.0, 0.0), (0.1, 0.0, q)) - 0.15
            # The tool sphere sits at (0, 0.2, q) + Rz(π/2)·(0.1, 0, 0) = (0, 0.3, q).
            expected_tool = math.dist((x, 0.0, 0.0), (0.0, 0.3, q)) - 0.12
            d = scene.distances([q], t)
            assert d[0, 0] == pytest.approx(expected_ball, abs=1e-9), (q, t)
            assert d[1, 0] == pytest.approx(expected_tool, abs=1e-9), (q, t)
            # The static twin stays where the comet started.
            assert d[0, 1] == pytest.approx(math.dist((1, 0, 0), (0.1, 0, q)) - 0.15, abs=1e-9)
            # The crate slides along y keeping its yaw: the ball in the crate's frame.
            ball = np.array([0.1, 0.0, q]) - [0.1, -1.0 + 0.25 * t, 0.1]
            c, s = math.cos(0.5), math.sin(0.5)
            local = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]) @ ball
            expected_crate = box_signed_distance(local, np.array([0.1, 0.15, 0.1])) - 0.05
            assert d[0, 2] == pytest.approx(expected_crate, abs=1e-7), (q, t)
            w = scene.witnesses([q], t)
            np.testing.assert_allclose(w.distance, d, atol=1e-12)
            if expected_ball > 0:
                # The comet's witness is on its surface, towards the ball.
                towards = np.array([0.1 - x, 0.0, q])
                np.testing.assert_allclose(
                    w.on_obstacle[0, 0],
                    [x, 0, 0] + 0.1 * towards / np.linalg.norm(towards),
                    atol=1e-7,
                )
    # Distance falls while the comet approaches, then rises after it passes.
    series = [scene.distances([0.0], t)[0, 0] for t in np.linspace(0.0, 9.0, 19)]
    lowest = int(np.argmin(series))
    assert 0 < lowest < len(series) - 1
    assert np.all(np.diff(series[: lowest + 1]) < 0) and np.all(np.diff(series[lowest:]) > 0)


# The ball on a continuous yaw joint before its slide, so that one joint can be locked.
TURN_URDF = BALL_URDF.replace(
    '<link name="base"/>',
    '<link name="base"/><joint name="yaw" type="continuous"><parent link="base"/>'
    '<child link="hub"/><axis xyz="0 0 1"/></joint><link name="hub"/>',
).replace('<parent link="base"/><child link="ball"/>', '<parent link="hub"/><child link="ball"/>')


def test_locked_joints_and_ee_offset_from_toml(tmp_path, write_toml):
    (tmp_path / "turn.urdf").write_text(TURN_URDF)
    robot_table = {
        "urdf": "turn.urdf",
        "locked_joints": {"yaw": 0.5},
        "ee_offset": {"xyz": [0.1, 0.0, 0.0], "rpy": [0.0, 0.0, 0.3]},
        "q0": [0.2],
    }
    path = write_toml({"robot": robot_table}, "scene.toml")
    scene, q0 = build_scene(load_scene_spec(load_toml(path)), tmp_path)
    robot = scene.robot
    assert robot.nq == 1 and robot.joint_names == ["slide"]
    np.testing.assert_array_equal(q0, [0.2])
    # Tool origin at (0, 0.2, q), yaw π/2; the offset moves 0.1 along the tool's x (world y);
    # the locked yaw turns all of it by 0.5 about z.
    c, s = math.cos(0.5), math.sin(0.5)
    expected = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ [0.0, 0.3, 0.2]
    np.testing.assert_allclose(robot.ee_position([0.2]), expected, atol=1e-12)
    yaw = 0.5 + math.pi / 2 + 0.3
    R = robot.ee_pose([0.2])[:3, :3]
    np.testing.assert_allclose(R[:2, 0], [math.cos(yaw), math.sin(yaw)], atol=1e-12)


@pytest.mark.parametrize(
    ("table", "field"),
    [
        ({"locked_joints": {"elbow": 0.0}}, "robot.locked_joints.elbow"),
        ({"locked_joints": {"slide": 2.0}}, "robot.locked_joints.slide"),
        ({"locked_joints": {"yaw": 7.0}}, "robot.locked_joints.yaw"),
        ({"locked_joints": {"yaw": 0.0, "slide": 0.0}}, "robot.locked_joints"),
        ({"ee_frame": "nope", "ee_offset": {"xyz": [0, 0, 0.1]}}, "robot.ee_frame"),
    ],
)
def test_locked_joint_and_ee_offset_errors_name_the_field(tmp_path, write_toml, table, field):
    (tmp_path / "turn.urdf").write_text(TURN_URDF)
    path = write_toml({"robot": {"urdf": "turn.urdf", **table}}, "scene.toml")
    with pytest.raises(ConfigError) as err:
        build_scene(load_scene_spec(load_toml(path)), tmp_path)
    assert err.value.field == field


@pytest.mark.parametrize(
    "table",
    [
        {"ee_offset": {"xyz": [0.0, 0.0]}},
        {"ee_offset": {"xyz": [0.0, 0.0, 1e9]}},
        {"ee_offset": {"rpy": [0.0, 0.0, 0.0], "scale": 2}},
        {"locked_joints": {"yaw": "half"}},
    ],
)
def test_robot_table_ee_offset_and_locked_joints_are_validated(table):
    with pytest.raises(ConfigError) as err:
        load_scene_spec({"robot": {"urdf": "turn.urdf", **table}})
    assert "robot" in str(err.value)


@pytest.mark.parametrize("robot_table", [{"urdf": "turn.urdf"}, {"builtin": "iiwa14"}])
def test_decomposing_an_unknown_link_names_robot_decompose(tmp_path, write_toml, robot_table):
    (tmp_path / "turn.urdf").write_text(TURN_URDF)
    path = write_toml({"robot": {**robot_table, "decompose": ["ball", "nope"]}}, "scene.toml")
    with pytest.raises(ConfigError) as err:
        build_scene(load_scene_spec(load_toml(path)), tmp_path)
    assert err.value.field == "robot.decompose"
    assert "'nope'" in err.value.problem and "the links are [" in err.value.problem


@pytest.mark.parametrize("decompose", ["ball", 1, [1], {"ball": True}])
def test_robot_decompose_is_a_boolean_or_link_names(decompose):
    with pytest.raises(ConfigError) as err:
        load_scene_spec({"robot": {"urdf": "turn.urdf", "decompose": decompose}})
    assert "robot.decompose" in str(err.value)


def test_robot_decompose_of_links_without_meshes_changes_nothing(tmp_path, write_toml):
    (tmp_path / "turn.urdf").write_text(TURN_URDF)
    path = write_toml({"robot": {"urdf": "turn.urdf", "decompose": True}}, "scene.toml")
    scene, _ = build_scene(load_scene_spec(load_toml(path)), tmp_path)
    assert [s.kind for link in scene.robot.links for s in link.shapes] == ["sphere", "sphere"]


@pytest.mark.parametrize("self_collision", [True, False])
def test_an_unknown_link_in_allow_pairs_is_an_error_even_with_self_collision_off(self_collision):
    robot = {"builtin": "iiwa14", "self_collision": self_collision,
             "allow_pairs": [["iiwa_link_1", "gripper"]]}  # fmt: skip
    with pytest.raises(ConfigError, match=r"robot\.allow_pairs.*no link 'gripper'"):
        build_scene(load_scene_spec({"robot": robot}), Path("."))


def test_self_collision_from_the_robot_table_checks_the_matrix_pairs():
    robot = {"builtin": "iiwa14", "self_collision": True,
             "allow_pairs": [["iiwa_link_7", "iiwa_link_5"]]}  # fmt: skip
    scene, _ = build_scene(load_scene_spec({"robot": robot}), Path("."))
    assert ("iiwa_link_0", "iiwa_link_5") in scene.self_pair_names
    assert ("iiwa_link_5", "iiwa_link_7") not in scene.self_pair_names
