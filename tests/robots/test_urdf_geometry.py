"""robots/urdf_geometry.py: each link's <collision> elements (box, cylinder, sphere and meshes by
relative, package:// and scaled references) become shapes at their origins, as the built robot
carries them; unusable elements name the link and the file. Chosen links' meshes are
decomposed by CoACD (cached) instead."""

from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull

from articula.errors import ConfigError, GeometryError, ModelError
from articula.geometry.poses import pose
from articula.geometry.shapes import sphere
from articula.robots import RobotModel, urdf_geometry
from articula.scene import Obstacle, Scene
from tests.geometry.test_meshes import NOTCH, U_OUTLINE, U_TRIANGLES
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


def _mesh_link(folder: Path, mesh: str):
    """The one link with shapes of a one-joint URDF whose tool link is the mesh file `mesh`."""
    (folder / "arm.urdf").write_text(
        '<robot name="r"><link name="base"/><link name="tool"><collision><geometry>'
        f'<mesh filename="{mesh}"/></geometry></collision></link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="tool"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    (link,) = [k for k in RobotModel.from_urdf(folder / "arm.urdf").links if k.shapes]
    return link


def test_a_link_mesh_of_separate_convex_parts_keeps_one_hull_per_part(tmp_path):
    tetra = "v {x} 0 0\nv {x1} 0 0\nv {x} 1 0\nv {x} 0 1\n"
    faces = "f {a} {c} {b}\nf {a} {b} {d}\nf {a} {d} {c}\nf {b} {c} {d}\n"
    obj = (tetra.format(x=0, x1=1) + faces.format(a=1, b=2, c=3, d=4)
           + tetra.format(x=3, x1=4) + faces.format(a=5, b=6, c=7, d=8))  # fmt: skip
    (tmp_path / "parts.obj").write_text(obj)
    link = _mesh_link(tmp_path, "parts.obj")
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


def test_a_link_mesh_with_holes_gives_its_hull(tmp_path):
    # Meshes of real arms are often not closed (the Panda's in pybullet_data); splitting them
    # into parts must not try to repair them (trimesh's repair needs networkx).
    closed = trimesh.creation.box(extents=(0.2, 0.4, 0.6))
    trimesh.Trimesh(closed.vertices, closed.faces[:-2]).export(tmp_path / "open.stl")
    link = _mesh_link(tmp_path, "open.stl")
    (hull,) = link.shapes
    _same_hull(hull.vertices, np.asarray(closed.vertices))


# ----- decompose: CoACD parts instead of the hull, for chosen links -----------------------------

# Link "u" (on a revolute joint) and link "twin" 0.5 m above it carry the same U-shaped mesh.
U_URDF = """<robot name="u"><link name="base"/>
  <joint name="turn" type="revolute"><parent link="base"/><child link="u"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="u"><collision><geometry><mesh filename="u.obj"/></geometry></collision></link>
  <joint name="fix" type="fixed"><parent link="u"/><child link="twin"/>
    <origin xyz="0 0 0.5"/></joint>
  <link name="twin"><collision><geometry><mesh filename="u.obj"/></geometry></collision></link>
</robot>"""


@pytest.fixture
def u_arm(tmp_path, monkeypatch) -> Path:
    """The U robot's URDF; decompositions cached in a folder of this test alone."""
    u = trimesh.creation.extrude_triangulation(0.1 * U_OUTLINE, U_TRIANGLES, 0.1)
    u.export(tmp_path / "u.obj")
    (tmp_path / "u.urdf").write_text(U_URDF)
    monkeypatch.setenv("ARTICULA_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "u.urdf"


def _notch_clearance(robot: RobotModel) -> float:
    """Distance [m] from link "u" to a 3 cm ball in its notch, 5 cm from the notch's walls."""
    ball = Obstacle("ball", (sphere(0.03),), pose(NOTCH, (0.0, 0.0, 0.0)))
    scene = Scene(robot, [ball])
    return float(scene.distances([0.0])[scene.link_names.index("u"), 0])


def test_a_decomposed_link_keeps_its_notch_free(u_arm):
    hulled = RobotModel.from_urdf(u_arm)
    decomposed = RobotModel.from_urdf(u_arm, decompose=["u"])
    shapes = {link.name: len(link.shapes) for link in decomposed.links}
    assert shapes["u"] >= 2 and shapes["twin"] == 1  # only the named link is decomposed
    assert [len(link.shapes) for link in hulled.links] == [1, 1]  # the default: the hull
    # The ball is 2 cm clear of the U, but 8 cm deep in its hull.
    assert _notch_clearance(hulled) < -0.05
    assert 0.01 < _notch_clearance(decomposed) < 0.025


def test_a_link_decomposition_is_cached_and_shared_by_links(u_arm, monkeypatch):
    import coacd

    runs = []
    real = coacd.run_coacd

    def counted(*args, **kwargs):
        runs.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(coacd, "run_coacd", counted)
    cache = u_arm.parent / "cache"
    first = RobotModel.from_urdf(u_arm, decompose=True)
    files = {f.name: f.stat().st_mtime_ns for f in cache.iterdir()}
    assert len(runs) == 1 and len(files) == 1  # both links' meshes are one decomposition
    again = RobotModel.from_urdf(u_arm, decompose=True)
    assert len(runs) == 1  # from the cache
    assert {f.name: f.stat().st_mtime_ns for f in cache.iterdir()} == files
    for a, b in zip(first.links, again.links, strict=True):
        assert len(a.shapes) == len(b.shapes) >= 2
        for s, t in zip(a.shapes, b.shapes, strict=True):
            np.testing.assert_array_equal(s.vertices, t.vertices)


@pytest.mark.parametrize("decompose", [["nope"], ["u", "nope", "base2"]])
def test_decomposing_an_unknown_link_names_the_field_and_the_links(u_arm, decompose):
    with pytest.raises(ConfigError) as exc:
        RobotModel.from_urdf(u_arm, decompose=decompose)
    assert exc.value.field == "decompose"
    assert "'nope'" in exc.value.problem and "['base', 'u', 'twin']" in exc.value.problem


def test_a_link_mesh_too_large_to_decompose_names_the_link_and_decompose(u_arm, monkeypatch):
    monkeypatch.setattr(urdf_geometry, "MAX_DECOMPOSE_VERTICES", 10)  # the U has 20
    with pytest.raises(GeometryError) as exc:
        RobotModel.from_urdf(u_arm, decompose=["twin"])
    assert "'twin'" in str(exc.value) and "u.obj" in str(exc.value)
    assert "out of decompose" in str(exc.value)
    assert len(RobotModel.from_urdf(u_arm).links) == 2  # the hulls need no limit
