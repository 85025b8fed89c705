"""geometry/meshes.py: mesh files and their errors, a mesh's convex hull and its CoACD parts,
against scipy's hulls and trimesh."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull

from articula.errors import GeometryError
from articula.geometry.meshes import convex_parts, load_mesh

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def _inside(points: np.ndarray, hull_points: np.ndarray, tol: float) -> np.ndarray:
    """Which points lie in the convex hull of hull_points, within tol [m] (face planes)."""
    eq = ConvexHull(hull_points).equations
    return (points @ eq[:, :3].T + eq[:, 3]).max(axis=1) <= tol


# ----- load_mesh --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("empty.stl", b"", ["empty.stl", "no vertices"]),
        ("empty.obj", b"", ["empty.obj", "no vertices"]),
        ("garbage.stl", b"\x00" * 10, ["garbage.stl"]),
        ("nan.obj", TETRA.replace("v 1 0 0", "v nan 0 0").encode(), ["nan.obj", "NaN"]),
        ("inf.obj", TETRA.replace("v 0 1 0", "v 0 inf 0").encode(), ["inf.obj", "infinite"]),
        (
            "nan.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\n"
            b"vertex 0 1 0\nendloop\nendfacet\nendsolid x\n",
            ["nan.stl", "NaN"],
        ),
        ("points.xyz", b"0 0 0\n1 0 0\n", ["points.xyz", "unsupported", ".stl"]),
        ("noext", TETRA.encode(), ["noext", "unsupported"]),
    ],
)
def test_unusable_mesh_files(tmp_path, name, content, words):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(GeometryError) as exc:
        load_mesh(path)
    for word in words:
        assert word in str(exc.value)


def test_missing_mesh_file(tmp_path):
    with pytest.raises(GeometryError, match=r"gone\.stl: mesh file not found"):
        load_mesh(tmp_path / "gone.stl")


@pytest.mark.parametrize("scale", [0.0, (1.0, 0.0, 1.0), math.nan, (1.0, 1.0, math.inf)])
def test_bad_scale(tmp_path, scale):
    path = tmp_path / "t.obj"
    path.write_text(TETRA)
    with pytest.raises(GeometryError, match="scale"):
        load_mesh(path, scale)


@pytest.mark.parametrize("ext", ["stl", "obj", "ply", "dae", "STL"])
def test_mesh_formats_round_trip_with_scale(tmp_path, ext):
    source = trimesh.creation.box(extents=(0.1, 0.2, 0.3))
    source.apply_translation([0.5, -0.25, 1.0])
    path = tmp_path / f"m.{ext}"
    source.export(path, file_type=ext.lower())
    mesh = load_mesh(path, (2.0, 1.0, 0.5))
    expected = np.array(source.bounds) * [2.0, 1.0, 0.5]
    np.testing.assert_allclose(mesh.bounds, expected, atol=1e-6)
    assert ConvexHull(mesh.vertices).volume == pytest.approx(0.006 * 2 * 0.5, rel=1e-5)
    assert mesh.faces.shape[1] == 3 and mesh.faces.max() < len(mesh.vertices)


def test_scene_file_is_merged_into_one_mesh(tmp_path):
    a = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    b = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    b.apply_translation([1.0, 0.0, 0.0])
    path = tmp_path / "two.dae"
    path.write_bytes(trimesh.exchange.dae.export_collada([a, b]))
    assert isinstance(trimesh.load(path), trimesh.Scene)  # two geometries in the file
    mesh = load_mesh(path)
    assert len(mesh.vertices) == 16
    np.testing.assert_allclose(mesh.bounds, [[-0.05, -0.05, -0.05], [1.05, 0.05, 0.05]], atol=1e-6)


def test_flat_mesh_loads_but_has_no_hull(tmp_path):
    path = tmp_path / "flat.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n")
    mesh = load_mesh(path)
    with pytest.raises(GeometryError) as exc:
        convex_parts(mesh, "plate")
    assert "plate" in str(exc.value) and "flat" in str(exc.value)


def test_open_mesh_still_gives_its_hull(tmp_path):
    closed = trimesh.creation.box(extents=(0.2, 0.4, 0.6))
    open_box = trimesh.Trimesh(closed.vertices, closed.faces[:-2], process=False)
    assert not open_box.is_watertight
    path = tmp_path / "open.stl"
    open_box.export(path)
    mesh = load_mesh(path)
    assert not mesh.is_watertight
    (part,) = convex_parts(mesh, "open")
    assert part.kind == "convex"
    assert ConvexHull(part.vertices).volume == pytest.approx(0.2 * 0.4 * 0.6, rel=1e-6)
    assert len(part.vertices) == 8


# ----- convex decomposition (CoACD) -------------------------------------------------------------

# A U: a 0.3 × 0.1 m bar with two 0.1 × 0.1 m arms, 0.1 m thick; the notch is x, y in [0.1, 0.2].
U_OUTLINE = np.array(
    [(0, 0), (3, 0), (3, 1), (3, 2), (2, 2), (2, 1), (1, 1), (1, 2), (0, 2), (0, 1)], float
)
U_TRIANGLES = np.array(
    [(0, 1, 2), (0, 2, 5), (0, 5, 6), (0, 6, 9), (5, 2, 3), (5, 3, 4), (9, 6, 7), (9, 7, 8)]
)
NOTCH = np.array([0.15, 0.15, 0.05])


@pytest.fixture(scope="module")
def u_shape() -> trimesh.Trimesh:
    mesh = trimesh.creation.extrude_triangulation(0.1 * U_OUTLINE, U_TRIANGLES, 0.1)
    assert mesh.is_watertight and mesh.volume == pytest.approx(0.005)
    return mesh


@pytest.fixture(scope="module")
def u_parts(u_shape):
    return convex_parts(u_shape, "u", decompose=True)


def test_hull_of_a_non_convex_mesh_covers_the_notch(u_shape):
    (hull,) = convex_parts(u_shape, "u")
    assert _inside(NOTCH[None], hull.vertices, 0.0)[0]
    assert ConvexHull(hull.vertices).volume == pytest.approx(0.3 * 0.2 * 0.1)


def test_decomposition_follows_the_concavity(u_shape, u_parts):
    assert len(u_parts) >= 2
    assert [p.kind for p in u_parts] == ["convex"] * len(u_parts)
    hull_points = np.asarray(u_shape.vertices)
    every_vertex = np.vstack([p.vertices for p in u_parts])
    assert _inside(every_vertex, hull_points, 1e-6).all()
    # The notch is inside the hull but outside every part.
    assert _inside(NOTCH[None], hull_points, 0.0)[0]
    for part in u_parts:
        assert not _inside(NOTCH[None], part.vertices, 0.02)[0]
    # The parts still cover the solid: every corner of the U is in some part.
    covered = np.zeros(len(hull_points), bool)
    for part in u_parts:
        covered |= _inside(hull_points, part.vertices, 1e-4)
    assert covered.all()
    total = sum(ConvexHull(p.vertices).volume for p in u_parts)
    assert 0.9 * 0.005 <= total <= 1.1 * 0.005


def test_decomposition_is_repeatable(u_shape, u_parts):
    again = convex_parts(u_shape, "u", decompose=True)
    assert len(again) == len(u_parts)
    for a, b in zip(again, u_parts, strict=True):
        np.testing.assert_array_equal(a.vertices, b.vertices)


@pytest.mark.parametrize("threshold", [0.0, -0.1, 1.5])
def test_decomposition_threshold_range(u_shape, threshold):
    with pytest.raises(GeometryError, match=r"u: threshold"):
        convex_parts(u_shape, "u", decompose=True, threshold=threshold)


def test_load_mesh_accepts_a_string_path(tmp_path):
    (tmp_path / "t.obj").write_text(TETRA)
    mesh = load_mesh(str(tmp_path / "t.obj"))  # type: ignore[arg-type]
    assert len(mesh.vertices) == 4


def test_decomposing_a_closed_stl_stays_inside_the_mesh(tmp_path):
    solid = trimesh.creation.box(extents=(0.3, 0.2, 0.1))
    solid.export(tmp_path / "box.stl")
    parts = convex_parts(load_mesh(tmp_path / "box.stl"), "box", decompose=True)
    every_vertex = np.vstack([p.vertices for p in parts])
    assert _inside(every_vertex, np.asarray(solid.vertices), 1e-6).all()


def test_decomposing_a_closed_obj_stays_inside_the_mesh(tmp_path):
    solid = trimesh.creation.box(extents=(0.3, 0.2, 0.1))
    solid.export(tmp_path / "box.obj")
    mesh = load_mesh(tmp_path / "box.obj")
    assert mesh.is_watertight
    parts = convex_parts(mesh, "box", decompose=True)
    every_vertex = np.vstack([p.vertices for p in parts])
    assert _inside(every_vertex, np.asarray(solid.vertices), 1e-6).all()
    assert sum(ConvexHull(p.vertices).volume for p in parts) == pytest.approx(0.006, rel=1e-3)


@pytest.mark.parametrize("scale", [1e308, 1e200, 1e-9, (1.0, 1e7, 1.0)])
def test_a_scale_outside_the_stated_range_is_refused_before_any_hull(tmp_path, scale):
    path = tmp_path / "t.obj"
    path.write_text(TETRA)
    with pytest.raises(GeometryError, match="scale"):
        load_mesh(path, scale)


def test_scaled_vertices_beyond_the_stated_length_are_refused(tmp_path):
    path = tmp_path / "t.obj"
    path.write_text(TETRA.replace("1 0 0", "3000 0 0"))
    with pytest.raises(GeometryError, match="beyond"):
        load_mesh(path, 10.0)


def test_a_decomposition_of_too_many_vertices_is_refused_naming_max_vertices():
    mesh = trimesh.creation.icosphere(subdivisions=3)  # 642 vertices
    with pytest.raises(GeometryError, match="max_vertices"):
        convex_parts(mesh, "ball", decompose=True, max_vertices=100)


def test_random_bytes_in_an_stl_are_a_geometry_error_not_a_missing_module(tmp_path):
    path = tmp_path / "noise.stl"
    path.write_bytes(np.random.default_rng(0).bytes(4096))
    with pytest.raises(GeometryError) as exc:
        load_mesh(path)
    assert "No module named" not in str(exc.value)


@pytest.mark.slow
def test_a_decomposition_is_cached_by_content_and_threshold(monkeypatch, decomposition_cache):
    import coacd

    calls = []
    real = coacd.run_coacd

    def counted(*args, **kwargs):
        calls.append(kwargs["threshold"])
        return real(*args, **kwargs)

    monkeypatch.setattr(coacd, "run_coacd", counted)
    mesh = trimesh.creation.annulus(r_min=0.3, r_max=0.5, height=0.2)
    first = convex_parts(mesh, "ring", decompose=True, threshold=0.1)
    again = convex_parts(mesh, "ring", decompose=True, threshold=0.1)
    assert calls == [0.1]  # the second came from the cache
    for a, b in zip(first, again, strict=True):
        np.testing.assert_array_equal(a.vertices, b.vertices)
    convex_parts(mesh, "ring", decompose=True, threshold=0.2)
    assert calls == [0.1, 0.2]  # another threshold is another decomposition
    assert len(list(decomposition_cache.glob("*.npz"))) >= 2
