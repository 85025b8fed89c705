"""How a Scene's shapes become the arrays of the compiled clearance path: GJK cores, hull-edge
adjacency, bounding-capsule ends, pair rows and the reach bound of the box pruning."""

from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull

from articula.geometry.shapes import ConvexShape


def _reach(placements: list, poses: list[np.ndarray], cores: list) -> float:
    """A bound [m] on the distance between any point of a link shape and any joint origin:
    every joint origin lies within Σ|joint offsets| of the base, and every shape point within
    that plus its own extent."""
    chain = float(sum(np.linalg.norm(p.translation) for p in placements))
    extent = max(
        (
            np.linalg.norm(T[:3, 3]) + float(np.max(np.linalg.norm(core[0], axis=1))) + core[1]
            for T, core in zip(poses, cores, strict=True)
        ),
        default=0.0,
    )
    return 2.0 * chain + extent


def _pair_rows(pairs: list[tuple[int, int, int, int]], index: dict) -> np.ndarray:
    """(shape a, shape b, cache row, kind, cell) rows of `pairs`."""
    rows = [(a, b, index[a, b, kind, cell], kind, cell) for a, b, kind, cell in pairs]
    return np.array(rows, dtype=np.int64).reshape(-1, 5)


def _core(shape: ConvexShape) -> tuple[np.ndarray, float] | None:
    """(core vertices, radius) of a shape, or None for a shape GJK here cannot represent."""
    if shape.kind in ("convex", "box"):
        return np.asarray(shape.vertices, dtype=float), 0.0
    if shape.kind == "sphere":
        return np.zeros((1, 3)), float(shape.geometry.radius)
    if shape.kind == "capsule":
        half = float(shape.geometry.halfLength)
        return np.array([[0.0, 0.0, -half], [0.0, 0.0, half]]), float(shape.geometry.radius)
    return None  # cylinders: round rims are not a swept polytope


def _edges(cores: list[np.ndarray], starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Hull-edge adjacency of every core as CSR arrays over the concatenated vertices; cores of
    one or two points (spheres, capsules) are joined completely."""
    lists: list[set[int]] = []
    for core, first in zip(cores, starts, strict=False):
        local = [set() for _ in range(len(core))]
        if len(core) >= 4:
            for tri in ConvexHull(core).simplices:
                for i in range(3):
                    a, b = int(tri[i]), int(tri[(i + 1) % 3])
                    local[a].add(b)
                    local[b].add(a)
        else:
            local = [set(range(len(core))) - {i} for i in range(len(core))]
        lists += [{int(first) + m for m in nbrs} for nbrs in local]
    offsets = np.cumsum([0] + [len(n) for n in lists]).astype(np.int64)
    flat = [m for nbrs in lists for m in sorted(nbrs)]
    return np.array(flat, dtype=np.int64), offsets


def _capsule_ends(shape: ConvexShape) -> tuple[np.ndarray, np.ndarray, float]:
    """The bounding capsule as its two segment ends (shape frame) and radius."""
    T, half = shape.bound.pose, shape.bound.length / 2
    return T[:3, 3] - half * T[:3, 2], T[:3, 3] + half * T[:3, 2], shape.bound.radius
