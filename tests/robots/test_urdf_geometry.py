"""robots/urdf_geometry.py: each link's <collision> elements (box, cylinder, sphere and meshes by
relative, package:// and scaled references) become shapes at their origins, as the built robot
carries them; unusable elements name the link and the file."""

from __future__ import annotations

import coal
import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull

from articula.errors import GeometryError, ModelError
from articula.robots import RobotModel
from tests.robots.helpers import HALF_PI, hom, rot_y, urdf_origin


def _vertices(mesh: trimesh.Trimesh) -> np.ndarray:
    return np.asarray(mesh.vertices, dtype=float)


def _same_hull(shape_vertices: np.ndarray, points: np.ndarray) -> None:
    """The shape is the convex hull of `points`: same volume, corners taken from the points."""
    assert ConvexHull(shape_vertices).volume == pytest.approx(ConvexHull(points).volume, rel=1e-6)
    gaps = np.min(np.linalg.norm(shape_vertices[:, None, :] - points[None, :, :], axis=2), axis=1)
    assert gaps.max() < 1e-6


@pytest.fixture
def links(small_arm) -> dict:
    """Link name -> LinkGeometry of the small arm."""
    robot = RobotModel.from_urdf(small_arm["urdf"], package_dirs=[small_arm["pkg"]])
    return {link.name: link for link in robot.links}


def test_box_element_with_a_translated_origin(links):
    (base,) = links["base"].shapes
    assert base.kind == "box"
    np.testing.assert_allclose(base.geometry.halfSide, [0.1, 0.15, 0.05])
    np.testing.assert_allclose(links["base"].placements[0], hom(p=(0, 0, 0.05)), atol=1e-12)


def test_cylinder_element_with_a_rotated_origin(links):
    (cyl,) = links["link1"].shapes
    assert cyl.kind == "cylinder" and isinstance(cyl.geometry, coal.Cylinder)
    assert cyl.geometry.radius == pytest.approx(0.05)
    assert cyl.geometry.halfLength == pytest.approx(0.15)
    np.testing.assert_allclose(
        links["link1"].placements[0], urdf_origin((0, 0, 0.15), (0.1, 0.2, 0.3)), atol=1e-12
    )


def test_sphere_and_scaled_stl_mesh_on_one_link(links, small_arm):
    ball, box_mesh = links["link2"].shapes
    assert ball.kind == "sphere" and ball.geometry.radius == pytest.approx(0.06)
    assert box_mesh.kind == "convex"
    _same_hull(box_mesh.vertices, _vertices(small_arm["a"]) * [2.0, 1.0, 1.0])
    np.testing.assert_allclose(links["link2"].placements[1], hom(p=(0.2, 0, 0)), atol=1e-12)


def test_package_obj_and_relative_dae_meshes_are_their_hulls(links, small_arm):
    obj, dae = links["link3"].shapes
    _same_hull(obj.vertices, _vertices(small_arm["b"]))
    _same_hull(dae.vertices, _vertices(small_arm["c"]))
    np.testing.assert_allclose(
        links["link3"].placements[1], hom(rot_y(HALF_PI), (0.05, 0, 0)), atol=1e-12
    )


def test_mesh_package_resolves_from_the_package_folder_itself(small_arm):
    # package_dirs may also name the package folder (package://mypkg/x -> DIR/x).
    robot = RobotModel.from_urdf(small_arm["urdf"], package_dirs=[small_arm["pkg"] / "mypkg"])
    assert len({link.name: link for link in robot.links}["link3"].shapes) == 2


def test_missing_mesh(small_arm):
    (small_arm["urdf"].parent / "meshes/a.stl").unlink()
    with pytest.raises(GeometryError) as exc:
        RobotModel.from_urdf(small_arm["urdf"], [small_arm["pkg"]])
    assert "a.stl" in str(exc.value) and "link2" in str(exc.value)


def test_unresolvable_package(small_arm):
    with pytest.raises(GeometryError) as exc:
        RobotModel.from_urdf(small_arm["urdf"])  # no package_dirs
    assert "package://mypkg/meshes/b.obj" in str(exc.value)
    assert "link3" in str(exc.value)


def test_unsupported_geometry_element(build_edited):
    with pytest.raises(ModelError, match="capsule"):
        build_edited('<sphere radius="0.06"/>', '<capsule radius="0.06"/>')


def test_non_positive_primitive_in_urdf(build_edited):
    with pytest.raises(GeometryError) as exc:
        build_edited('<sphere radius="0.06"/>', '<sphere radius="-0.06"/>')
    assert "sphere" in str(exc.value) and "link2" in str(exc.value)


def test_a_link_mesh_of_separate_convex_parts_keeps_one_hull_per_part(tmp_path):
    tetra = "v {x} 0 0\nv {x1} 0 0\nv {x} 1 0\nv {x} 0 1\n"
    faces = "f {a} {c} {b}\nf {a} {b} {d}\nf {a} {d} {c}\nf {b} {c} {d}\n"
    obj = (tetra.format(x=0, x1=1) + faces.format(a=1, b=2, c=3, d=4)
           + tetra.format(x=3, x1=4) + faces.format(a=5, b=6, c=7, d=8))  # fmt: skip
    (tmp_path / "parts.obj").write_text(obj)
    (tmp_path / "arm.urdf").write_text(
        '<robot name="r"><link name="base"/><link name="tool"><collision><geometry>'
        '<mesh filename="parts.obj"/></geometry></collision></link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="tool"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    (link,) = [k for k in RobotModel.from_urdf(tmp_path / "arm.urdf").links if k.shapes]
    assert len(link.shapes) == 2
    # A point in the gap between the parts is outside both, though inside their common hull.
    gap = coal.Sphere(0.01)
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    for shape in link.shapes:
        result.clear()
        away = coal.distance(shape.geometry, coal.Transform3s(), gap,
                             coal.Transform3s(np.eye(3), np.array([2.0, 0.1, 0.1])), request,
                             result)  # fmt: skip
        assert away > 0.5
