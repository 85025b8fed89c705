"""robots/model.py: iiwa14 kinematics against a hand-written joint table, Jacobians against finite
differences, the shipped collision hulls against the original meshes, and a small URDF's joints,
kinematics and refusals."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from articula.errors import ConfigError, ModelError
from articula.robots import RobotModel
from tests.robots.helpers import (
    HALF_PI,
    central_differences,
    hom,
    rot_y,
    rot_z,
    urdf_origin,
)

ROOT = Path(__file__).resolve().parents[2]
MESHES = ROOT / "src/articula/robots/data/iiwa14/meshes"
ORIGINAL_VERTICES = ROOT / "tests/data/iiwa14_mesh_vertices.npz"

# ----- a plain-numpy forward kinematics, written from the published lbr_iiwa joint table --------

# (joint origin xyz [m], rpy [rad]) of iiwa_joint_1..7; every joint turns about its own z axis.
IIWA_JOINTS = [
    ((0.0, 0.0, 0.1575), (0.0, 0.0, 0.0)),
    ((0.0, 0.0, 0.2025), (HALF_PI, 0.0, math.pi)),
    ((0.0, 0.2045, 0.0), (HALF_PI, 0.0, math.pi)),
    ((0.0, 0.0, 0.2155), (HALF_PI, 0.0, 0.0)),
    ((0.0, 0.1845, 0.0), (-HALF_PI, math.pi, 0.0)),
    ((0.0, 0.0, 0.2155), (HALF_PI, 0.0, 0.0)),
    ((0.0, 0.081, 0.0), (-HALF_PI, math.pi, 0.0)),
]
FLANGE = 0.045  # m along z of link 7
LIMITS_DEG = [170, 120, 170, 120, 170, 120, 175]
SHOULDER_Z = 0.1575 + 0.2025  # 0.36 m: joint 2 axis
ELBOW_Z = SHOULDER_Z + 0.2045 + 0.2155  # 0.78 m: joint 4 axis
WRIST_Z = ELBOW_Z + 0.1845 + 0.2155  # 1.18 m: joint 6 axis
REACH = WRIST_Z + 0.081 + FLANGE  # 1.306 m


def hand_link_frames(q) -> list[np.ndarray]:
    """World poses of iiwa_link_0..7 and the flange (9 matrices)."""
    frames = [np.eye(4)]
    for (xyz, rpy), qi in zip(IIWA_JOINTS, q, strict=True):
        frames.append(frames[-1] @ urdf_origin(xyz, rpy) @ hom(rot_z(qi)))
    frames.append(frames[-1] @ hom(p=(0.0, 0.0, FLANGE)))
    return frames


def hand_ee(q) -> np.ndarray:
    return hand_link_frames(q)[-1]


@pytest.fixture(scope="module")
def iiwa() -> RobotModel:
    return RobotModel.builtin("iiwa14")


def random_q(rng: np.random.Generator, robot: RobotModel) -> np.ndarray:
    return rng.uniform(robot.lower, robot.upper)


# ----- iiwa14 forward kinematics ---------------------------------------------------------------


def test_iiwa_structure_and_limits(iiwa):
    assert iiwa.nq == 7
    assert iiwa.joint_names == [f"iiwa_joint_{i}" for i in range(1, 8)]
    assert iiwa.ee_frame == "iiwa_link_ee"
    np.testing.assert_allclose(iiwa.upper, np.deg2rad(LIMITS_DEG), atol=1e-9)
    np.testing.assert_allclose(iiwa.lower, -np.deg2rad(LIMITS_DEG), atol=1e-9)
    # Every link with a collision mesh, base to tip; the flange has none.
    assert [link.name for link in iiwa.links] == [f"iiwa_link_{k}" for k in range(8)]


def test_iiwa_home_pose(iiwa):
    T = iiwa.ee_pose(np.zeros(7))
    np.testing.assert_allclose(T[:3, 3], [0.0, 0.0, 1.306], atol=1e-9)
    np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-9)
    np.testing.assert_allclose(T[3], [0, 0, 0, 1], atol=0)
    np.testing.assert_allclose(iiwa.ee_position([0] * 7), [0.0, 0.0, REACH], atol=1e-9)


@pytest.mark.parametrize("q2", [HALF_PI, -HALF_PI])
def test_iiwa_shoulder_at_right_angle_lays_the_arm_flat(iiwa, q2):
    # Joint 2 turns about world +y at home (its frame is Rz(π)·Rx(π/2)), so q2 = ±π/2 lays the
    # straight arm along ±x at shoulder height, 1.306 − 0.36 m from the shoulder.
    q = [0.0, q2, 0.0, 0.0, 0.0, 0.0, 0.0]
    expected = [math.copysign(REACH - SHOULDER_Z, q2), 0.0, SHOULDER_Z]
    np.testing.assert_allclose(iiwa.ee_position(q), expected, atol=1e-9)


def test_iiwa_base_rotation_turns_the_flat_arm(iiwa):
    theta = 0.7
    q = [theta, HALF_PI, 0.0, 0.0, 0.0, 0.0, 0.0]
    r = REACH - SHOULDER_Z
    expected = [r * math.cos(theta), r * math.sin(theta), SHOULDER_Z]
    np.testing.assert_allclose(iiwa.ee_position(q), expected, atol=1e-9)


@pytest.mark.parametrize(("joint", "pivot_z"), [(3, ELBOW_Z), (5, WRIST_Z)], ids=["elbow", "wrist"])
def test_iiwa_bending_one_joint_keeps_the_distance_to_its_axis(iiwa, joint, pivot_z):
    # Bending joint 4 (or 6) by π/2 swings the rest of the arm into the horizontal plane of
    # that joint's axis, at the same distance from it.
    q = np.zeros(7)
    q[joint] = HALF_PI
    ee = iiwa.ee_position(q)
    assert ee[2] == pytest.approx(pivot_z, abs=1e-9)
    assert np.linalg.norm(ee - [0.0, 0.0, pivot_z]) == pytest.approx(REACH - pivot_z, abs=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_iiwa_poses_match_the_joint_table(iiwa, seed):
    q = random_q(np.random.default_rng(seed), iiwa)
    frames = hand_link_frames(q)
    np.testing.assert_allclose(iiwa.ee_pose(q), frames[-1], atol=1e-9)
    poses = iiwa.link_poses(q)
    assert set(poses) == {f"iiwa_link_{k}" for k in range(8)} | {"iiwa_link_ee"}
    for k in range(8):
        np.testing.assert_allclose(poses[f"iiwa_link_{k}"], frames[k], atol=1e-9)
    np.testing.assert_allclose(poses["iiwa_link_ee"], frames[-1], atol=1e-9)


def test_iiwa_specific_configuration(iiwa):
    q = [0.3, -0.5, 1.1, -1.4, 0.6, 1.2, -2.0]
    T = hand_ee(q)
    np.testing.assert_allclose(iiwa.ee_pose(q), T, atol=1e-9)
    np.testing.assert_allclose(iiwa.ee_position(np.array(q)), T[:3, 3], atol=1e-9)


def test_ee_pose_returns_a_copy(iiwa):
    T = iiwa.ee_pose(np.zeros(7))
    T[:3, 3] = 99.0
    assert iiwa.ee_position(np.zeros(7))[2] == pytest.approx(REACH, abs=1e-9)


@pytest.mark.parametrize(
    "q",
    [np.zeros(6), np.zeros(8), [[0.0] * 7], [0, 0, 0, math.nan, 0, 0, 0], [math.inf] + [0] * 6],
    ids=["short", "long", "2d", "nan", "inf"],
)
def test_check_q_rejects_bad_configurations(iiwa, q):
    with pytest.raises(ConfigError) as exc:
        iiwa.ee_position(q)
    assert exc.value.field == "q"
    with pytest.raises(ConfigError) as exc:
        iiwa.check_q(q, "robot.q0")
    assert exc.value.field == "robot.q0"


def test_check_q_accepts_lists_and_ints(iiwa):
    arr = iiwa.check_q([0, 1, 0, 0, 0, 0, 0])
    assert arr.dtype == np.float64 and arr.shape == (7,)
    np.testing.assert_array_equal(arr, [0, 1, 0, 0, 0, 0, 0])


def test_unknown_builtin_robot():
    with pytest.raises(ConfigError) as exc:
        RobotModel.builtin("ur5")
    assert exc.value.field == "builtin"
    assert "iiwa14" in str(exc.value)


# ----- Jacobian against finite differences -----------------------------------------------------


@pytest.mark.parametrize("seed", range(5))
def test_iiwa_jacobian_matches_finite_differences(iiwa, seed):
    q = random_q(np.random.default_rng(100 + seed), iiwa)
    J = iiwa.jacobian(q)
    assert J.shape == (6, 7)
    h = 1e-6
    numeric = np.zeros((6, 7))
    for i in range(7):
        dq = np.zeros(7)
        dq[i] = h
        plus, minus = hand_ee(q + dq), hand_ee(q - dq)
        numeric[:3, i] = (plus[:3, 3] - minus[:3, 3]) / (2 * h)
        # Angular velocity in world axes: log(R(q+h) R(q−h)ᵀ) / 2h.
        numeric[3:, i] = Rotation.from_matrix(plus[:3, :3] @ minus[:3, :3].T).as_rotvec() / (2 * h)
        # The library's own position, differentiated, agrees as well.
        lib = (iiwa.ee_position(q + dq) - iiwa.ee_position(q - dq)) / (2 * h)
        np.testing.assert_allclose(J[:3, i], lib, atol=1e-7)
    np.testing.assert_allclose(J, numeric, atol=1e-7)


def test_iiwa_jacobian_at_home_by_hand(iiwa):
    # At home every axis is vertical or horizontal: joint 1 (z) does not move the flange, and
    # joint 2 (axis +y through z = 0.36) moves it along +x at 1.306 − 0.36 m/rad.
    J = iiwa.jacobian(np.zeros(7))
    np.testing.assert_allclose(J[:, 0], [0, 0, 0, 0, 0, 1], atol=1e-9)
    np.testing.assert_allclose(J[:, 1], [REACH - SHOULDER_Z, 0, 0, 0, 1, 0], atol=1e-9)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_directional_gradients_match_finite_differences_of_a_point_fixed_to_a_link(iiwa, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(0.8 * iiwa.lower, 0.8 * iiwa.upper)
    local = rng.normal(scale=0.1, size=3)  # a point in the link frame, off its origin

    for link in iiwa.links[2::2] + iiwa.links[-1:]:

        def world_point(qq, frame=link.frame_id):
            iiwa.forward(qq)
            T = iiwa.data.oMf[frame].homogeneous
            return T[:3, :3] @ local + T[:3, 3]

        p = world_point(q)
        # Along the three axes the rows are the point's Jacobian.
        J = iiwa.directional_gradients(q, [link.frame_id] * 3, np.array([p] * 3), np.eye(3))
        assert J.shape == (3, iiwa.nq)
        assert np.allclose(J, central_differences(world_point, q, 1e-6), atol=1e-7), link.name
        # Joints after the link's own joint (index j moves q[j - 1]) do not move the point.
        assert np.all(J[:, iiwa.model.frames[link.frame_id].parentJoint :] == 0)


# ----- shipped collision hulls -----------------------------------------------------------------


def _shipped_hull(k: int) -> ConvexHull:
    mesh = trimesh.load(MESHES / f"link_{k}.stl", force="mesh", process=False)
    return ConvexHull(np.asarray(mesh.vertices, dtype=float))


def _worst_excursion(k: int) -> float:
    """Largest signed distance [m] of an original link-k vertex beyond a shipped hull face."""
    hull = _shipped_hull(k)
    original = np.load(ORIGINAL_VERTICES)[f"link_{k}"]
    assert original.ndim == 2 and original.shape[1] == 3 and len(original) > 100
    return float((original @ hull.equations[:, :3].T + hull.equations[:, 3]).max())


@pytest.mark.parametrize("k", range(8))
def test_shipped_hull_contains_original_vertices_to_float32_precision(k):
    # The STL stores the hull corners as float32: near 0.3 m that is 1.5e-8 m per coordinate.
    assert _worst_excursion(k) <= 1e-8


def test_shipped_hulls_contain_original_vertices_within_1e9():
    worst = {k: _worst_excursion(k) for k in range(8)}
    assert max(worst.values()) <= 1e-9, worst


@pytest.mark.parametrize("k", range(8))
def test_shipped_hull_is_close_to_the_exact_hull(k):
    original = np.load(ORIGINAL_VERTICES)[f"link_{k}"]
    exact = ConvexHull(original)
    shipped = _shipped_hull(k)
    assert shipped.volume >= exact.volume * (1 - 1e-9)
    assert shipped.volume <= exact.volume * 1.05
    # docs/deviations.md: at most 7.9 mm beyond the exact hull (the farthest point of a
    # polytope from a convex set is one of its corners).
    exact_mesh = trimesh.Trimesh(original, exact.simplices, process=False)
    _, reach, _ = trimesh.proximity.closest_point_naive(
        exact_mesh, shipped.points[shipped.vertices]
    )
    assert reach.max() <= 7.9e-3 + 1e-4


def test_builtin_link_shapes_are_the_shipped_hulls(iiwa):
    for k, link in enumerate(iiwa.links):
        assert len(link.shapes) == 1
        np.testing.assert_allclose(link.placements[0], np.eye(4), atol=0)
        shipped = _shipped_hull(k)
        got = ConvexHull(link.shapes[0].vertices)
        assert got.volume == pytest.approx(shipped.volume, rel=1e-9)
        assert len(got.vertices) == len(shipped.vertices)


# ----- a small URDF of our own -----------------------------------------------------------------


def test_small_urdf_joints_limits_and_links_with_collision_geometry(small_arm):
    robot = RobotModel.from_urdf(small_arm["urdf"], package_dirs=[small_arm["pkg"]])
    assert robot.nq == 3
    assert robot.joint_names == ["j1", "j2", "j3"]
    np.testing.assert_allclose(robot.lower, [-3, -2, 0])
    np.testing.assert_allclose(robot.upper, [3, 2, 0.2])
    links = [link.name for link in robot.links]
    assert links == ["base", "link1", "link2", "link3"]  # tool has no collision


def hand_small_ee(q) -> np.ndarray:
    """Tool position of the small arm: Tz(.1) Rz(q1) Tz(.3) Ry(q2) Tx(.4 + q3) Tx(.1)."""
    q1, q2, q3 = q
    return rot_z(q1) @ (rot_y(q2) @ [0.5 + q3, 0.0, 0.0] + [0.0, 0.0, 0.3]) + [0.0, 0.0, 0.1]


@pytest.mark.parametrize(
    "q", [(0.0, 0.0, 0.0), (HALF_PI, 0.0, 0.1), (0.4, -0.9, 0.05), (-2.5, 1.7, 0.2)]
)
def test_small_urdf_forward_kinematics(small_arm, q):
    robot = RobotModel.from_urdf(small_arm["urdf"], package_dirs=[small_arm["pkg"]])
    assert robot.ee_frame == "tool"  # the last link by default
    np.testing.assert_allclose(robot.ee_position(q), hand_small_ee(q), atol=1e-12)
    R = robot.ee_pose(q)[:3, :3]
    np.testing.assert_allclose(R, rot_z(q[0]) @ rot_y(q[1]), atol=1e-12)
    poses = robot.link_poses(q)
    np.testing.assert_allclose(poses["link2"][:3, 3], rot_z(q[0]) @ [0, 0, 0.3] + [0, 0, 0.1])


def test_small_urdf_configurable_ee_frame(small_arm):
    robot = RobotModel.from_urdf(
        small_arm["urdf"], package_dirs=[small_arm["pkg"]], ee_frame="link2"
    )
    q = (0.3, 0.8, 0.1)
    np.testing.assert_allclose(robot.ee_position(q), rot_z(0.3) @ [0, 0, 0.3] + [0, 0, 0.1])
    # The Jacobian is that of the chosen frame: the prismatic joint does not move link2.
    np.testing.assert_allclose(robot.jacobian(q)[:, 2], 0.0, atol=1e-12)


def test_small_urdf_prismatic_jacobian_column(small_arm):
    robot = RobotModel.from_urdf(small_arm["urdf"], package_dirs=[small_arm["pkg"]])
    q = (0.3, 0.8, 0.1)
    # Sliding the prismatic joint moves the tool along link 2's x axis, without rotation.
    axis = rot_z(0.3) @ rot_y(0.8) @ [1.0, 0.0, 0.0]
    np.testing.assert_allclose(robot.jacobian(q)[:, 2], [*axis, 0, 0, 0], atol=1e-12)


def test_missing_urdf(tmp_path):
    with pytest.raises(ConfigError) as exc:
        RobotModel.from_urdf(tmp_path / "nope.urdf")
    assert exc.value.field == "urdf"
    assert "nope.urdf" in str(exc.value)


def test_unknown_ee_frame(small_arm):
    with pytest.raises(ConfigError) as exc:
        RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]], ee_frame="gripper")
    assert exc.value.field == "ee_frame"
    assert "gripper" in str(exc.value)


def test_a_joint_of_two_degrees_of_freedom_is_rejected(build_edited):
    with pytest.raises(ModelError, match="j2"):
        build_edited('name="j2" type="revolute"', 'name="j2" type="floating"')


def _chain_urdf(links: int) -> str:
    """A URDF chain of `links` links, each 0.1 m above the last on a revolute joint."""
    body = "".join(f'<link name="l{i}"/>' for i in range(links))
    body += "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        '<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(links - 1)
    )
    return f'<robot name="r">{body}</robot>'


@pytest.mark.slow
def test_a_urdf_over_the_link_limit_is_refused_before_pinocchio_reads_it(tmp_path):
    path = tmp_path / "long.urdf"
    path.write_text(_chain_urdf(300))
    with pytest.raises(ConfigError) as err:
        RobotModel.from_urdf(path)
    assert "max_links = 300" in err.value.problem
    assert RobotModel.from_urdf(path, max_links=300).nq == 299


def test_what_the_urdf_parser_prints_ends_up_in_the_one_error(tmp_path, capfd):
    path = tmp_path / "bad.urdf"
    path.write_text(
        '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
        '<parent link="a"/><child link="b"/></joint></robot>'
    )  # a revolute joint without limits: urdfdom prints its complaint on stderr
    with pytest.raises(ModelError) as err:
        RobotModel.from_urdf(path)
    assert "does not specify limits" in str(err.value)
    assert capfd.readouterr() == ("", "")


def test_joint_origins_beyond_the_stated_length_are_refused(tmp_path):
    path = tmp_path / "far.urdf"
    path.write_text(_chain_urdf(3).replace('xyz="0 0 0.1"', 'xyz="0 0 1e300"'))
    with pytest.raises(ModelError, match="origin"):
        RobotModel.from_urdf(path)


def test_joint_values_beyond_the_stated_angle_are_refused():
    robot = RobotModel.builtin("iiwa14")
    with pytest.raises(ConfigError, match="within"):
        robot.check_q([1e308] + [0.0] * 6)


def test_the_end_effector_frame_of_the_built_in_robot_can_be_chosen_and_is_checked():
    assert RobotModel.builtin("iiwa14", "iiwa_link_7").ee_frame == "iiwa_link_7"
    with pytest.raises(ConfigError) as err:
        RobotModel.builtin("iiwa14", "nope")
    assert err.value.field == "ee_frame"
