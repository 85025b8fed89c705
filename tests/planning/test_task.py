"""planning/task.py and reference_velocity.task_rows: orientation errors against scipy, the pose
and axis Jacobian rows against finite differences, and the targets a [trajectory] carries."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from articula.errors import ConfigError
from articula.planning.clearance import RowSource
from articula.planning.config import TrajectorySpec, make_targets
from articula.planning.reference_velocity import rotation_vector, task_rows
from articula.planning.task import Target, Task
from articula.robots import RobotModel
from articula.scene import Scene
from articula.validation import parse_model
from tests.robots.helpers import central_differences

ROBOT = RobotModel.builtin("iiwa14")
Q = np.array([0.3, 0.5, -0.4, -1.1, 0.6, 0.8, -0.2])


@pytest.mark.parametrize("angle", [1e-7, 1e-3, 0.5, 2.0, 3.1])
def test_pose_error_is_the_rotation_angle_between_the_frames(angle):
    rng = np.random.default_rng(int(angle * 1e7) % 1000)
    R_ref = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
    axis = rng.normal(size=3)
    R = R_ref @ Rotation.from_rotvec(angle * axis / np.linalg.norm(axis)).as_matrix()
    error = Task("pose").orientation_error(R, Target(np.zeros(3), R_ref))
    assert error == pytest.approx(angle, rel=1e-6, abs=1e-12)


@pytest.mark.parametrize("angle", [0.0, 1e-6, 0.3, 1.5, 3.0])
def test_axis_error_is_the_angle_between_tool_axis_and_reference(angle):
    tool = np.array([0.0, 1.0, 1.0]) / np.sqrt(2)
    R = Rotation.from_rotvec([0.2, -0.4, 0.7]).as_matrix()
    a = R @ tool
    normal = np.cross(a, [1.0, 0.0, 0.0])
    reference = Rotation.from_rotvec(angle * normal / np.linalg.norm(normal)).as_matrix() @ a
    task = Task("position+axis", tool_axis=tool)
    error = task.orientation_error(R, Target(np.zeros(3), axis=reference))
    assert error == pytest.approx(angle, abs=1e-9)
    assert Task("position").orientation_error(R, Target(np.zeros(3))) == 0.0


def rotation_at(q: np.ndarray) -> np.ndarray:
    return ROBOT.ee_pose(q)[:3, :3]


def rows_at(task: Task, target: Target) -> tuple[np.ndarray, np.ndarray]:
    """task_rows at Q, the end effector from the compiled kinematics (RowSource)."""
    ee, _ = RowSource(Scene(ROBOT, []))(Q, 0.0, 0.15)
    return task_rows(ee.x, ee.R, ee.J, task, target, None, 0.01, 1.0)


def test_pose_rows_are_the_jacobian_of_position_and_rotation():
    target = Target(np.zeros(3), np.eye(3))
    J, _ = rows_at(Task("pose"), target)
    fd_x = central_differences(lambda q: ROBOT.ee_position(q), Q, 1e-6)
    # Rotation rows: ω with R(q + δq) ≈ exp(ω̂ δt) R(q), world axes.
    R0 = rotation_at(Q)
    fd_w = central_differences(lambda q: pin.log3(rotation_at(q) @ R0.T), Q, 1e-6)
    assert np.allclose(J[:3], fd_x, atol=1e-7)
    assert np.allclose(J[3:], fd_w, atol=1e-7)


def test_axis_rows_move_the_tool_axis_as_finite_differences_do():
    tool = np.array([0.0, 0.0, 1.0])
    task = Task("position+axis", tool_axis=tool)
    J, _ = rows_at(task, Target(np.zeros(3), axis=tool))
    assert J.shape == (5, ROBOT.nq)
    a = rotation_at(Q) @ tool
    fd_a = central_differences(lambda q: rotation_at(q) @ tool, Q, 1e-6)  # ȧ per joint
    basis = _basis_across(J, Q, a)
    for j in range(ROBOT.nq):
        # ȧ = ω × a, so a × ȧ = ω − (a·ω) a: the part of ω that turns the axis, which the two
        # rows must give in their basis.
        assert np.allclose(J[3:, j], basis @ np.cross(a, fd_a[:, j]), atol=1e-7)


def _basis_across(J: np.ndarray, q: np.ndarray, a: np.ndarray) -> np.ndarray:
    """The two unit rows the axis rows use, recovered: orthonormal, perpendicular to a."""
    full = ROBOT.jacobian(q)[3:]
    basis = np.linalg.lstsq(full.T, J[3:].T, rcond=None)[0].T
    assert np.allclose(basis @ a, 0.0, atol=1e-9)
    assert np.allclose(basis @ basis.T, np.eye(2), atol=1e-9)
    return basis


def test_rotation_vector_turns_a_onto_b():
    rng = np.random.default_rng(5)
    for _ in range(20):
        a, b = (v / np.linalg.norm(v) for v in rng.normal(size=(2, 3)))
        turned = Rotation.from_rotvec(rotation_vector(a, b)).apply(a)
        assert np.allclose(turned, b, atol=1e-12)


def test_a_pose_task_needs_an_orientation_and_an_axis_task_an_axis():
    with pytest.raises(ConfigError, match=r"target.*pose task needs a target orientation"):
        Task("pose").orientation_error(np.eye(3), Target(np.zeros(3)))
    with pytest.raises(ConfigError, match=r"target.*needs a target axis"):
        Task("position+axis").orientation_error(np.eye(3), Target(np.zeros(3)))
    with pytest.raises(ConfigError, match="tool_axis"):
        Task("position+axis", tool_axis=np.zeros(3))


def test_trajectory_orientations_fixed_and_interpolated_between_waypoints():
    fixed = make_targets(TrajectorySpec(type="circle", center=[0, 0.6, 0.5], axis_a=[1, 0, 0],
                                        axis_b=[0, 0, 1], radius=0.1, period=5.0,
                                        quaternion=[0.0, 1.0, 0.0, 0.0]), Path("."))  # fmt: skip
    assert np.allclose(fixed(1.3).rotation, np.diag([1.0, -1.0, -1.0]))
    spec = TrajectorySpec(type="waypoints", points=[[0.4, 0, 0.5], [0.4, 0.2, 0.5]],
                          times=[0.0, 2.0], rpys=[[0, 0, 0], [0, 0, 1.2]])  # fmt: skip
    targets = make_targets(spec, Path("."))
    assert np.allclose(targets(1.0).rotation, Rotation.from_rotvec([0, 0, 0.6]).as_matrix())
    assert np.allclose(targets(5.0).rotation, Rotation.from_rotvec([0, 0, 1.2]).as_matrix())
    line = TrajectorySpec(type="waypoints", points=[[0.4, 0, 0.5], [0.4, 0.2, 0.5]],
                          times=[0, 1], axis=[0, 0, -2], cone=0.1)  # fmt: skip
    axis = make_targets(line, Path("."))
    assert np.allclose(axis(0.5).axis, [0, 0, -1]) and axis.cone == 0.1


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ({"rpy": [0, 0, 0], "quaternion": [1, 0, 0, 0]}, "one orientation"),
        ({"cone": 0.1}, "cone needs an axis"),
        ({"rpys": [[0, 0, 0], [0, 0, 1]]}, "need type = 'waypoints'"),
    ],
)
def test_bad_orientation_keys_are_refused(extra, message):
    circle = dict(type="circle", center=[0, 0.6, 0.5], axis_a=[1, 0, 0], axis_b=[0, 0, 1],
                  radius=0.1, period=5.0)  # fmt: skip
    with pytest.raises(ConfigError, match=message):
        parse_model(TrajectorySpec, circle | extra, "trajectory")


def test_a_wrong_count_of_waypoint_quaternions_names_quaternions():
    spec = TrajectorySpec(type="waypoints", points=[[0.4, 0, 0.5], [0.4, 0.2, 0.5]],
                          times=[0.0, 2.0], quaternions=[[1, 0, 0, 0]])  # fmt: skip
    with pytest.raises(ConfigError, match=r"trajectory\.quaternions: needs 2 orientations"):
        make_targets(spec, Path("."))


@pytest.mark.parametrize(
    ("header", "rows"),
    [("t,x,y,z,roll,pitch,yaw", ["0,0.4,0,0.5,0,0,0", "2,0.4,0.2,0.5,0,0,1.2"]),
     ("t,x,y,z,qw,qx,qy,qz",
      ["0,0.4,0,0.5,1,0,0,0", f"2,0.4,0.2,0.5,{np.cos(0.6)},0,0,{np.sin(0.6)}"])],
    ids=["rpy", "quaternion"],
)  # fmt: skip
def test_a_csv_trajectory_carries_an_orientation_per_row(tmp_path, header, rows):
    (tmp_path / "path.csv").write_text("\n".join([header, *rows]) + "\n")
    targets = make_targets(TrajectorySpec(type="csv", path="path.csv"), tmp_path)
    assert np.allclose(targets(1.0).position, [0.4, 0.1, 0.5])
    assert np.allclose(targets(1.0).rotation, Rotation.from_rotvec([0, 0, 0.6]).as_matrix())


def test_a_csv_trajectory_without_orientation_columns_has_none(tmp_path):
    (tmp_path / "path.csv").write_text("t,x,y,z\n0,0.4,0,0.5\n1,0.4,0.1,0.5\n")
    assert make_targets(TrajectorySpec(type="csv", path="path.csv"), tmp_path)(0.5).rotation is None


@pytest.mark.parametrize(
    ("text", "message"),
    [("t,x,y,z,roll,pitch\n0,0,0,0,0,0\n1,1,0,0,0,0\n", "optionally with roll, pitch, yaw"),
     ("t,x,y,z,roll,pitch,yaw\n0,0,0,0,0,nan,0\n1,1,0,0,0,0,0\n", "must be finite")],
)  # fmt: skip
def test_bad_csv_orientation_columns_are_refused(tmp_path, text, message):
    (tmp_path / "path.csv").write_text(text)
    with pytest.raises(ConfigError, match=rf"trajectory\.path.*{message}"):
        make_targets(TrajectorySpec(type="csv", path="path.csv"), tmp_path)
