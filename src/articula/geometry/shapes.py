"""Convex solids for distance queries: hulls of point sets and the usual primitives."""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import trimesh

from articula.errors import GeometryError
from articula.geometry.bounds import Capsule, bounding_capsule

# Round primitives are also kept as tessellations, for bounds and for the book's vertex metric.
_SECTIONS = 32


@dataclass(frozen=True, eq=False)
class ConvexShape:
    """A convex solid in its own frame: its coal geometry, vertices and a bounding capsule.

    `vertices` are exact for polytopes and a fine tessellation (on the surface) for round
    primitives; `bound` contains the solid itself, not only the tessellation.

    Attributes:
        kind: the solid's type: "convex", "box", "sphere", "cylinder" or "capsule".
        geometry: the coal collision geometry used for the distance queries.
        vertices: vertices in the shape frame, shape (n, 3) [m].
        bound: bounding capsule for the broad phase, in the shape frame.
    """

    kind: str
    geometry: coal.ShapeBase
    vertices: np.ndarray
    bound: Capsule


def convex_hull(points: np.ndarray, name: str = "points") -> ConvexShape:
    """Convex hull of an (n, 3) point set; GeometryError if it is empty, non-finite or flat.

    Args:
        points: the points to wrap, shape (n, 3) [m].
        name: what the points are, for the error messages.

    Returns:
        The convex hull as a shape of kind "convex".
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
        raise GeometryError(f"{name}: need an (n, 3) array of vertices (got shape {pts.shape})")
    if not np.all(np.isfinite(pts)):
        raise GeometryError(f"{name}: vertices contain NaN or infinite values")
    centered = pts - pts.mean(axis=0)
    if len(pts) < 4 or np.linalg.matrix_rank(centered, tol=1e-9 * max(1.0, np.abs(pts).max())) < 3:
        raise GeometryError(f"{name}: the vertices are flat (no volume); a solid needs thickness")
    hull = trimesh.convex.convex_hull(pts)
    vertices = np.asarray(hull.vertices, dtype=float)
    if hull.volume <= 0:
        raise GeometryError(f"{name}: the convex hull has no volume")
    # Faces are kept so that coal can walk the hull by neighbours (fast support queries).
    geometry = coal.Convex.convexHull(_vec3s(vertices), True, None)
    return ConvexShape("convex", geometry, vertices, bounding_capsule(vertices))


def box(size: tuple[float, float, float]) -> ConvexShape:
    """Box with edge lengths `size` [m], centred on its frame.

    Args:
        size: edge lengths along x, y and z [m].

    Returns:
        The box, with its 8 corners as vertices.
    """
    x, y, z = _positive("box", size, 3)
    half = 0.5 * np.array([x, y, z])
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    return ConvexShape("box", coal.Box(x, y, z), corners, bounding_capsule(corners))


def sphere(radius: float) -> ConvexShape:
    """Sphere of `radius` [m] centred on its frame.

    Args:
        radius: radius of the sphere [m].

    Returns:
        The sphere, with an icosphere tessellation as vertices.
    """
    (r,) = _positive("sphere", (radius,), 1)
    vertices = np.asarray(trimesh.creation.icosphere(subdivisions=2, radius=r).vertices)
    return ConvexShape("sphere", coal.Sphere(r), vertices, Capsule(np.eye(4), r, 0.0))


def cylinder(radius: float, length: float) -> ConvexShape:
    """Cylinder of `radius` and `length` [m] along its z axis, centred on its frame.

    Args:
        radius: radius of the cylinder [m].
        length: length of the cylinder along z [m].

    Returns:
        The cylinder, with a tessellation as vertices.
    """
    r, h = _positive("cylinder", (radius, length), 2)
    vertices = np.asarray(
        trimesh.creation.cylinder(radius=r, height=h, sections=_SECTIONS).vertices
    )
    return ConvexShape("cylinder", coal.Cylinder(r, h), vertices, Capsule(np.eye(4), r, h))


def capsule(radius: float, length: float) -> ConvexShape:
    """Capsule: a cylinder of `radius` and `length` [m] along z with hemispherical caps.

    Args:
        radius: radius of the cylinder and of the caps [m].
        length: length of the cylinder along z, between the centres of the caps [m].

    Returns:
        The capsule, with a tessellation as vertices.
    """
    r, h = _positive("capsule", (radius, length), 2)
    mesh = trimesh.creation.capsule(height=h, radius=r, count=[_SECTIONS, _SECTIONS])
    vertices = np.asarray(mesh.vertices)
    return ConvexShape("capsule", coal.Capsule(r, h), vertices, Capsule(np.eye(4), r, h))


def _positive(kind: str, values: tuple[float, ...], count: int) -> tuple[float, ...]:
    vals = tuple(float(v) for v in np.atleast_1d(np.asarray(values, dtype=float)))
    if len(vals) != count or not all(np.isfinite(v) and v > 0 for v in vals):
        raise GeometryError(f"{kind}: needs {count} finite positive size(s) in m (got {values})")
    return vals


def _vec3s(points: np.ndarray) -> coal.StdVec_Vec3s:
    out = coal.StdVec_Vec3s()
    out.extend(list(np.asarray(points, dtype=float)))
    return out
