"""The built-in UR5e (robots/data/ur5e, from Universal Robots' ROS 2 description): its tool
frame agrees with the closed form of UR's published DH parameters, its limits are the
datasheet's, its link masses UR's and every link has its collision mesh."""

from __future__ import annotations

import numpy as np
import pytest

from articula.robots import RobotModel

# UR's DH parameters of the UR5e (universal-robots.com, "DH parameters for calculations of
# kinematics and dynamics"): d, a [m] and alpha [rad] of joints 1..6.
D = [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996]
A = [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0]
ALPHA = [np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0]


def _dh_tool_pose(q: np.ndarray) -> np.ndarray:
    """Pose (4×4) of the tool flange in base_link by the DH closed form; UR's Base frame is
    base_link turned π about z."""
    T = np.diag([-1.0, -1.0, 1.0, 1.0])
    for theta, d, a, alpha in zip(q, D, A, ALPHA, strict=True):
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        T = T @ np.array(
            [[ct, -st * ca, st * sa, a * ct],
             [st, ct * ca, -ct * sa, a * st],
             [0.0, sa, ca, d],
             [0.0, 0.0, 0.0, 1.0]]
        )  # fmt: skip
    return T


@pytest.fixture(scope="module")
def ur5e() -> RobotModel:
    return RobotModel.builtin("ur5e")


@pytest.mark.parametrize("seed", range(5))
def test_the_tool_pose_matches_the_dh_closed_form_to_a_micrometre(ur5e, seed):
    rng = np.random.default_rng(seed)
    for q in rng.uniform(*ur5e.sample_range, size=(200, 6)):
        pose = ur5e.ee_pose(q)
        expected = _dh_tool_pose(q)
        assert np.max(np.abs(pose[:3, 3] - expected[:3, 3])) < 1e-6  # [m]
        assert np.max(np.abs(pose[:3, :3] - expected[:3, :3])) < 1e-8


def test_at_zero_the_arm_lies_along_minus_x_of_base_link_reversed(ur5e):
    # UR's zero pose: the arm stretched along the Base frame's -x, which is base_link's +x
    position = ur5e.ee_position(np.zeros(6))
    assert np.allclose(position, [0.425 + 0.3922, 0.1333 + 0.0996, 0.1625 - 0.0997], atol=1e-9)


def test_limits_are_the_datasheets(ur5e):
    assert ur5e.joint_names == [
        "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
        "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]  # fmt: skip
    assert np.allclose(ur5e.velocity_limit, np.pi)  # 180 °/s
    assert np.allclose(ur5e.model.effortLimit, [150, 150, 150, 28, 28, 28])
    assert np.allclose(ur5e.upper, [2 * np.pi, 2 * np.pi, np.pi, *[2 * np.pi] * 3])
    assert np.allclose(ur5e.lower, -ur5e.upper)


def test_the_moving_links_have_urs_masses_and_every_link_its_mesh(ur5e):
    masses = [inertia.mass for inertia in ur5e.model.inertias[1:]]
    assert masses == pytest.approx([3.761, 8.058, 2.846, 1.37, 1.3, 0.365])  # [kg] UR's table
    moving = [link.name for link in ur5e.links if link.shapes]
    assert moving == ["base_link_inertia", "shoulder_link", "upper_arm_link", "forearm_link",
                      "wrist_1_link", "wrist_2_link", "wrist_3_link"]  # fmt: skip
