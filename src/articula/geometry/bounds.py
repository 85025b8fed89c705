"""Bounding volumes for the broad phase: a capsule that contains every vertex."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Capsule:
    """Segment of `length` [m] along the z axis of `pose` (4×4, shape frame), `radius` [m].

    Attributes:
        pose: pose of the capsule in the shape frame, shape (4, 4); the segment is centred on
            its origin and runs along its z axis [m].
        radius: distance from the segment that the capsule reaches [m].
        length: length of the segment between the centres of the two caps [m].
    """

    pose: np.ndarray
    radius: float
    length: float


def bounding_capsule(vertices: np.ndarray) -> Capsule:
    """A capsule around the principal axis of the vertices that contains all of them.

    The radius is the largest distance from the axis; each end of the segment is pulled in as
    far as the vertices allow (a vertex at axial position t and distance ρ stays inside while
    the end is within sqrt(r² − ρ²) of t).

    Args:
        vertices: points to contain, shape (n, 3) [m].

    Returns:
        The bounding capsule, in the frame of the vertices.
    """
    pts = np.asarray(vertices, dtype=float)
    mean = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - mean, full_matrices=True)  # three axes even for few points
    axis = vt[0]
    t = (pts - mean) @ axis
    rho = np.linalg.norm((pts - mean) - np.outer(t, axis), axis=1)
    radius = float(rho.max())
    reach = np.sqrt(np.maximum(radius**2 - rho**2, 0.0))
    lo, hi = float(np.min(t + reach)), float(np.max(t - reach))
    if hi < lo:  # round enough that a sphere does it
        lo = hi = 0.5 * (lo + hi)
    # Guard against rounding: the last bits of the fit must never exclude a vertex.
    radius *= 1.0 + 1e-9
    R = np.column_stack([vt[1], np.cross(axis, vt[1]), axis])
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = mean + axis * 0.5 * (lo + hi)
    return Capsule(T, radius, hi - lo)
