"""Plan configs of real arms among obstacles, shared by the tests: a Franka Panda (pybullet_data)
circling past a box, a ball and a mesh (the "Panda tight scene"), a Universal Robots UR10 and UR5
and a Kinova Jaco 2 (example-robot-data) and the built-in UR5e each circling past a ball."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import pytest

CONFIGS = Path(__file__).resolve().parents[1] / "src/articula/book/ch1/configs"
PANDA_HOME = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]  # [rad] libfranka's ready pose
UR10_HOME = [0.0, -1.57, 1.57, -1.57, -1.57, 0.0]  # [rad]
JACO2_HOME = [4.80, 2.92, 1.00, 4.20, 1.44, 1.32]  # [rad] kinova-ros's home, continuous 1, 4, 6
CIRCLE = {"type": "circle", "axis_a": [0.0, 1.0, 0.0], "axis_b": [0.0, 0.0, 1.0], "period": 10.0}


def pybullet_data() -> Path:
    """pybullet_data's folder (the test skips without pybullet)."""
    data = pytest.importorskip("pybullet_data")
    return Path(data.getDataPath())


def robot_data() -> Path:
    """The `share` folder of example-robot-data, whose robots/ its package:// paths name (the
    test skips without it: pip install example-robot-data)."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("needs example-robot-data: pip install example-robot-data")
    return Path(str(dist.locate_file("cmeel.prefix/share")))


def panda_robot() -> dict:
    """The Franka Panda of pybullet_data, its fingers locked, at libfranka's ready pose."""
    folder = pybullet_data() / "franka_panda"
    return {"urdf": str(folder / "panda.urdf"), "package_dirs": [str(folder)],
            "locked_joints": {"panda_finger_joint1": 0.02}, "q0": PANDA_HOME}  # fmt: skip


def ur10_robot() -> dict:
    """The UR10 of example-robot-data."""
    share = robot_data()
    urdf = share / "example-robot-data/robots/ur_description/urdf/ur10_robot.urdf"
    return {"urdf": str(urdf), "package_dirs": [str(share)], "q0": UR10_HOME}


def ur5_robot() -> dict:
    """The UR5 (CB3) of example-robot-data, at the UR10's home."""
    share = robot_data()
    urdf = share / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
    return {"urdf": str(urdf), "package_dirs": [str(share)], "q0": UR10_HOME}


def ur5e_robot() -> dict:
    """The UR5e shipped with articula (robots/data/ur5e), at the UR10's home."""
    return {"builtin": "ur5e", "q0": UR10_HOME}


def jaco2_robot(q0: list[float] | None = None) -> dict:
    """The Kinova Jaco 2 (j2s6s200) of example-robot-data, at kinova-ros's home (or `q0`)."""
    share = robot_data()
    urdf = share / "example-robot-data/robots/kinova_description/robots/kinova.urdf"
    return {"urdf": str(urdf), "package_dirs": [str(share)], "q0": q0 or JACO2_HOME}


def arm_scene(name: str, duration: float = 12.0) -> dict:
    """A plan config of one arm circling past obstacles, with the [planner] defaults but for
    Λ, d_min and the run's length: "panda" (a box, a ball and a mesh; d_min 5 mm), "xarm6" (a
    ball and a box), "ur10" (a ball; d_min 20 mm), "ur5" or "ur5e" (a ball; d_min 15 mm) or "jaco2"
    (a ball; d_min 10 mm)."""
    planner = {"lambda_weight": 0.002, "d_min": 0.005, "duration": duration, "settle": 2.0}
    if name == "panda":
        return {"robot": panda_robot(), "planner": planner,
                "trajectory": {**CIRCLE, "center": [0.45, 0.0, 0.45], "radius": 0.15},
                "obstacles": [
                    {"name": "box", "box": [0.2, 0.1, 0.1], "position": [0.45, -0.28, 0.35]},
                    {"name": "ball", "sphere": 0.05, "position": [0.3, 0.22, 0.62]},
                    {"name": "rock", "mesh": str(CONFIGS / "rock.stl"), "scale": 0.5,
                     "position": [0.62, 0.1, 0.2]}]}  # fmt: skip
    if name == "ur10":
        return {"robot": ur10_robot(), "planner": {**planner, "d_min": 0.02},
                "trajectory": {**CIRCLE, "center": [0.7, 0.16, 0.55], "radius": 0.15},
                "obstacles": [{"name": "ball", "sphere": 0.06,
                               "position": [0.66, 0.40, 0.66]}]}  # fmt: skip
    if name == "ur5":  # the UR10's scene scaled to the UR5's reach (≈ 2/3)
        return {"robot": ur5_robot(), "planner": {**planner, "d_min": 0.015},
                "trajectory": {**CIRCLE, "center": [0.49, 0.11, 0.37], "radius": 0.07},
                "obstacles": [{"name": "ball", "sphere": 0.04,
                               "position": [0.46, 0.27, 0.44]}]}  # fmt: skip
    if name == "ur5e":  # the UR5's scene moved with the tool at home (+5 mm x, +24 y, +56 z)
        return {"robot": ur5e_robot(), "planner": {**planner, "d_min": 0.015},
                "trajectory": {**CIRCLE, "center": [0.50, 0.13, 0.43], "radius": 0.07},
                "obstacles": [{"name": "ball", "sphere": 0.04,
                               "position": [0.47, 0.29, 0.50]}]}  # fmt: skip
    if name == "jaco2":
        return {"robot": jaco2_robot(), "planner": {**planner, "d_min": 0.01},
                "trajectory": {**CIRCLE, "center": [0.18, -0.23, 0.40], "radius": 0.06},
                "obstacles": [{"name": "ball", "sphere": 0.04,
                               "position": [0.26, -0.10, 0.36]}]}  # fmt: skip
    folder = pybullet_data() / "xarm"
    return {"robot": {"urdf": str(folder / "xarm6_robot.urdf"), "package_dirs": [str(folder)],
                      "q0": [0.0, -0.3, -0.6, 0.0, 0.9, 0.0]},
            "planner": planner,
            "trajectory": {**CIRCLE, "center": [0.4, 0.0, 0.3], "radius": 0.12},
            "obstacles": [{"name": "ball", "sphere": 0.05, "position": [0.3, 0.25, 0.35]},
                          {"name": "box", "box": [0.1, 0.1, 0.3],
                           "position": [0.45, -0.25, 0.15]}]}  # fmt: skip
