"""robots/urdf_visuals.py: a URDF's <visual> elements as meshes, poses and colours."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ModelError
from articula.robots.urdf_visuals import visual_meshes

URDF = """<robot name="r">
  <material name="blue"><color rgba="0 0 1 1"/></material>
  <link name="a">
    <visual><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><box size="0.1 0.2 0.3"/></geometry>
      <material name="blue"/></visual>
    <visual><geometry><sphere radius="0.05"/></geometry>
      <material name="red"><color rgba="1 0 0 0.5"/></material></visual>
  </link>
  <link name="b"><visual><geometry><cylinder radius="0.02" length="0.4"/></geometry></visual></link>
</robot>"""


def test_primitives_their_poses_and_colours(tmp_path):
    path = tmp_path / "r.urdf"
    path.write_text(URDF)
    v = visual_meshes(path)
    box, ball = v["a"]
    assert np.allclose(box.mesh.extents, [0.1, 0.2, 0.3])
    assert np.allclose(box.placement[:3, 3], [0, 0, 0.1])
    assert box.rgba == (0.0, 0.0, 1.0, 1.0)  # the robot-level material, by name
    assert ball.rgba == (1.0, 0.0, 0.0, 0.5)  # an inline colour
    assert np.allclose(np.linalg.norm(ball.mesh.vertices, axis=1), 0.05)
    (rod,) = v["b"]
    assert np.allclose(rod.mesh.extents, [0.04, 0.04, 0.4], atol=1e-3) and rod.rgba is None


def test_a_missing_mesh_file_is_a_model_error(tmp_path):
    path = tmp_path / "r.urdf"
    mesh = '<geometry><mesh filename="nowhere.stl"/></geometry>'
    path.write_text(f'<robot name="r"><link name="a"><visual>{mesh}</visual></link></robot>')
    with pytest.raises(ModelError, match=r"nowhere\.stl"):
        visual_meshes(path)
