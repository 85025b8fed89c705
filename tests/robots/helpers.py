"""Hand-written kinematics shared by the robot tests: rotations, homogeneous transforms, URDF
origins, and a small three-joint URDF whose collision geometry covers every element kind."""

from __future__ import annotations

import math

import numpy as np

HALF_PI = math.pi / 2


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def hom(R: np.ndarray | None = None, p=(0.0, 0.0, 0.0)) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def urdf_origin(xyz, rpy) -> np.ndarray:
    """URDF <origin>: translate, then fixed-axis roll, pitch, yaw (R = Rz(y) Ry(p) Rx(r))."""
    r, p, y = rpy
    return hom(rot_z(y) @ rot_y(p) @ rot_x(r), xyz)


# Box, cylinder, sphere, a scaled STL, an OBJ in a package and a DAE with a rotated origin; a
# prismatic third joint and a tool frame without collision geometry.
SMALL_URDF = """<?xml version="1.0"?>
<robot name="small">
  <link name="base">
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.3 0.1"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <link name="link1">
    <collision><origin xyz="0 0 0.15" rpy="0.1 0.2 0.3"/>
      <geometry><cylinder radius="0.05" length="0.3"/></geometry></collision>
  </link>
  <joint name="j2" type="revolute">
    <parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <link name="link2">
    <collision><geometry><sphere radius="0.06"/></geometry></collision>
    <collision><origin xyz="0.2 0 0"/>
      <geometry><mesh filename="meshes/a.stl" scale="2 1 1"/></geometry></collision>
  </link>
  <joint name="j3" type="prismatic">
    <parent link="link2"/><child link="link3"/>
    <origin xyz="0.4 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" effort="1" velocity="1"/>
  </joint>
  <link name="link3">
    <collision><geometry><mesh filename="package://mypkg/meshes/b.obj"/></geometry></collision>
    <collision><origin xyz="0.05 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><mesh filename="c.dae"/></geometry></collision>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="link3"/><child link="tool"/>
    <origin xyz="0.1 0 0"/>
  </joint>
  <link name="tool"/>
</robot>
"""


def central_differences(f, q: np.ndarray, h: float) -> np.ndarray:
    """Central differences of f (array-valued) along each joint: shape (*f.shape, nq)."""
    cols = []
    for j in range(q.size):
        e = np.zeros(q.size)
        e[j] = h
        cols.append((f(q + e) - f(q - e)) / (2 * h))
    return np.stack(cols, axis=-1)
