"""GJK distance between two convex polytopes (each optionally swept by a sphere), compiled.

Shapes are stored as "core + radius": the vertices of a polytope with radius 0, the centre of
a sphere, or the two ends of a capsule's segment with the capsule's radius. The distance is
the core distance minus both radii. Only clearance is computed: overlapping shapes give 0
(no penetration depth), which is all the planner's objective needs (Eqs. 1.7, 1.12).
"""

from __future__ import annotations

import math

import numpy as np

from articula.numba_cache import jit
from articula.scene.gjk_simplex import _closest_on_simplex, _dot

_MAX_ITERATIONS = 64
_RELATIVE_TOLERANCE = 1e-12  # stop when |v|² − v·w <= tol·|v|² (Gilbert et al. 1988)


@jit()
def _support(
    vertices: np.ndarray,
    neighbours: np.ndarray,
    offsets: np.ndarray,
    hint: int,
    R: np.ndarray,
    p: np.ndarray,
    dx: float,
    dy: float,
    dz: float,
    out: np.ndarray,
    sign: float,
) -> int:
    """out += sign · (the vertex of a posed core (R, p) furthest along world direction d);
    returns that vertex's index.

    Hill climbing over the hull's edges from vertex `hint`: on a convex polytope a vertex that
    no neighbour beats is the maximum of a linear function, so this visits a few dozen
    vertices instead of all of them.
    """
    # Direction in the shape frame: Rᵀ d, so the vertices are never transformed.
    lx = R[0, 0] * dx + R[1, 0] * dy + R[2, 0] * dz
    ly = R[0, 1] * dx + R[1, 1] * dy + R[2, 1] * dz
    lz = R[0, 2] * dx + R[1, 2] * dy + R[2, 2] * dz
    k = hint
    best = vertices[k, 0] * lx + vertices[k, 1] * ly + vertices[k, 2] * lz
    while True:  # steepest ascent: move to the best neighbour while one is better
        k_next = k
        for e in range(offsets[k], offsets[k + 1]):
            m = neighbours[e]
            s = vertices[m, 0] * lx + vertices[m, 1] * ly + vertices[m, 2] * lz
            if s > best:
                best = s
                k_next = m
        if k_next == k:
            break
        k = k_next
    _add_vertex(vertices, k, R, p, out, sign)
    return k


@jit()
def _add_vertex(
    vertices: np.ndarray, k: int, R: np.ndarray, p: np.ndarray, out: np.ndarray, sign: float
) -> None:
    """out += sign · (R vertices[k] + p): vertex k of a core posed at (R, p)."""
    x, y, z = vertices[k, 0], vertices[k, 1], vertices[k, 2]
    for i in range(3):
        out[i] += sign * (R[i, 0] * x + R[i, 1] * y + R[i, 2] * z + p[i])


@jit()
def gjk_distance(
    vertices: np.ndarray,
    neighbours: np.ndarray,
    offsets: np.ndarray,
    hints: np.ndarray,
    a: int,
    R_a: np.ndarray,
    p_a: np.ndarray,
    radius_a: float,
    b: int,
    R_b: np.ndarray,
    p_b: np.ndarray,
    radius_b: float,
    simplex: np.ndarray,
) -> float:
    """Distance [m] between two posed cores a and b swept by their radii; 0 when they overlap.

    `vertices` holds every core; `neighbours[offsets[k]:offsets[k + 1]]` are the vertices
    joined to vertex k by a hull edge; `hints[a]` is a vertex of core a where its support
    search starts, updated to the last support found (successive queries are close, so the
    climb is short; the answer does not depend on the hint). `simplex` is this pair's
    warm start, updated on return: the count n and the (A, B) vertex indices of the last
    final simplex, (n, a0, b0, a1, b1, a2, b2), n = 0 for none. GJK restarts from those
    vertices at the new poses (Bergen's caching): a query close to the last one converges in
    one or two iterations instead of rebuilding its simplex point by point.

    Args:
        vertices: the hull vertices of every core, stacked, shape (V, 3) [m, core frame].
        neighbours: the hull-edge adjacency of all vertices, concatenated, shape (E,).
        offsets: where each vertex's neighbours start in `neighbours`, shape (V + 1,).
        hints: a start vertex per core for the support search, shape (cores,); updated.
        a: index of core A.
        R_a: rotation of core A, shape (3, 3).
        p_a: position of core A, shape (3,) [m].
        radius_a: radius swept around core A (0 for a polytope) [m].
        b: index of core B.
        R_b: rotation of core B, shape (3, 3).
        p_b: position of core B, shape (3,) [m].
        radius_b: radius swept around core B [m].
        simplex: this pair's warm start (n, a0, b0, a1, b1, a2, b2), shape (7,); updated.

    Returns:
        The distance between the two swept shapes, 0 when they overlap [m].
    """
    return _gjk(
        vertices, neighbours, offsets, hints, a, R_a, p_a, radius_a, b, R_b, p_b, radius_b, simplex
    )[0]


@jit()
def gjk_witnesses(
    vertices: np.ndarray,
    neighbours: np.ndarray,
    offsets: np.ndarray,
    hints: np.ndarray,
    a: int,
    R_a: np.ndarray,
    p_a: np.ndarray,
    radius_a: float,
    b: int,
    R_b: np.ndarray,
    p_b: np.ndarray,
    radius_b: float,
    simplex: np.ndarray,
    on_a: np.ndarray,
    on_b: np.ndarray,
) -> float:
    """gjk_distance, and the closest points of the two shapes' surfaces [m, world] written to
    on_a and on_b; when the shapes overlap (0 returned) on_a and on_b are left as they were.

    The points come from the final simplex: the closest point of A − B is Σ λ_i w_i with
    w_i = a_i − b_i, so Σ λ_i a_i is a closest point of core A and that minus the closest
    point of A − B one of core B; each moves by its radius along the normal to the surface.

    Args:
        vertices: the hull vertices of every core, stacked, shape (V, 3) [m, core frame].
        neighbours: the hull-edge adjacency of all vertices, concatenated, shape (E,).
        offsets: where each vertex's neighbours start in `neighbours`, shape (V + 1,).
        hints: a start vertex per core for the support search, shape (cores,); updated.
        a: index of core A.
        R_a: rotation of core A, shape (3, 3).
        p_a: position of core A, shape (3,) [m].
        radius_a: radius swept around core A [m].
        b: index of core B.
        R_b: rotation of core B, shape (3, 3).
        p_b: position of core B, shape (3,) [m].
        radius_b: radius swept around core B [m].
        simplex: this pair's warm start (n, a0, b0, a1, b1, a2, b2), shape (7,); updated.
        on_a: written with the closest point on A's surface, shape (3,) [m, world].
        on_b: written with the closest point on B's surface, shape (3,) [m, world].

    Returns:
        The distance between the two swept shapes, 0 when they overlap [m].
    """
    d, W, Wa, n = _gjk(
        vertices, neighbours, offsets, hints, a, R_a, p_a, radius_a, b, R_b, p_b, radius_b, simplex
    )
    if n == 0:
        return d
    weights = _barycentric(W, n)
    for k in range(3):
        v_k = 0.0
        a_k = 0.0
        for i in range(n):
            v_k += weights[i] * W[i, k]
            a_k += weights[i] * Wa[i, k]
        on_a[k] = a_k
        on_b[k] = a_k - v_k
    gap = math.sqrt(_dot(on_a - on_b, on_a - on_b))
    if gap > 0.0:
        for k in range(3):
            normal = (on_a[k] - on_b[k]) / gap
            on_a[k] -= radius_a * normal
            on_b[k] += radius_b * normal
    return d


@jit()
def _barycentric(W: np.ndarray, n: int) -> np.ndarray:
    """Weights λ (Σ λ = 1) of the point of the affine hull of W[:n] (n ≤ 3) closest to the
    origin; GJK's reduced simplex holds it in its relative interior."""
    weights = np.zeros(n)
    if n == 1:
        weights[0] = 1.0
        return weights
    e1 = W[1] - W[0]
    if n == 2:
        denom = _dot(e1, e1)
        t = -_dot(W[0], e1) / denom if denom > 0.0 else 0.0
        weights[0], weights[1] = 1.0 - t, t
        return weights
    e2 = W[2] - W[0]  # solve the 2×2 normal equations of min |W0 + s e1 + t e2|
    a11, a12, a22 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
    b1, b2 = -_dot(W[0], e1), -_dot(W[0], e2)
    det = a11 * a22 - a12 * a12
    if det <= 1e-300:
        weights[0] = 1.0
        return weights
    s = (b1 * a22 - b2 * a12) / det
    t = (a11 * b2 - a12 * b1) / det
    weights[0], weights[1], weights[2] = 1.0 - s - t, s, t
    return weights


@jit()
def _gjk(
    vertices: np.ndarray,
    neighbours: np.ndarray,
    offsets: np.ndarray,
    hints: np.ndarray,
    a: int,
    R_a: np.ndarray,
    p_a: np.ndarray,
    radius_a: float,
    b: int,
    R_b: np.ndarray,
    p_b: np.ndarray,
    radius_b: float,
    simplex: np.ndarray,
) -> tuple[float, np.ndarray, np.ndarray, int]:
    """GJK itself: (distance, the final simplex W of A − B, the A supports Wa of its vertices,
    its size n; 0 when the shapes overlap), from and back into the `simplex` cache."""
    # Three allocations, the rest views: this runs a few hundred times per control period.
    scratch = np.empty((13, 3))
    W, Wa = scratch[0:4], scratch[4:8]
    trial, w, support_a, v, v_new = scratch[8], scratch[9], scratch[10], scratch[11], scratch[12]
    flags = np.zeros(8, dtype=np.bool_)
    keep, best_keep = flags[0:4], flags[4:8]
    ids = np.empty((4, 2), dtype=np.int64)  # (A vertex, B vertex) of each simplex point
    hint_a, hint_b = hints[a], hints[b]
    n = _cached_simplex(
        vertices, R_a, p_a, R_b, p_b, simplex, W, Wa, ids, keep, best_keep, trial, v
    )
    if n == 0:
        # No usable cache: start from a point of A − B along the centres' offset.
        dx, dy, dz = p_b[0] - p_a[0], p_b[1] - p_a[1], p_b[2] - p_a[2]
        if dx == 0.0 and dy == 0.0 and dz == 0.0:
            dx = 1.0
        Wa[0] = 0.0
        hint_a = _support(vertices, neighbours, offsets, hint_a, R_a, p_a, dx, dy, dz, Wa[0], 1.0)
        W[0] = Wa[0]
        hint_b = _support(
            vertices, neighbours, offsets, hint_b, R_b, p_b, -dx, -dy, -dz, W[0], -1.0
        )
        ids[0, 0], ids[0, 1] = hint_a, hint_b
        v[:] = W[0]
        n = 1
    lower = 0.0
    for _ in range(_MAX_ITERATIONS):
        # w = s_A(−v) − s_B(v), the support of A − B towards the origin.
        dx, dy, dz = -v[0], -v[1], -v[2]
        support_a[:] = 0.0
        hint_a = _support(
            vertices, neighbours, offsets, hint_a, R_a, p_a, dx, dy, dz, support_a, 1.0
        )
        w[:] = support_a
        hint_b = _support(vertices, neighbours, offsets, hint_b, R_b, p_b, -dx, -dy, -dz, w, -1.0)
        vv = _dot(v, v)
        vw = _dot(v, w)
        if vw > 0.0:
            # Every point of A − B lies beyond the plane through w normal to v: a lower
            # bound of the core distance, whatever stops the loop.
            lower = max(lower, vw / math.sqrt(vv))
        if vv - vw <= _RELATIVE_TOLERANCE * vv:
            break
        W[n] = w
        Wa[n] = support_a
        ids[n, 0], ids[n, 1] = hint_a, hint_b
        n += 1
        n = _closest_on_simplex(W, Wa, ids, n, keep, best_keep, trial, v_new)
        vv_new = _dot(v_new, v_new)
        if n == 4 or vv_new <= 1e-24:
            hints[a] = hint_a
            hints[b] = hint_b
            simplex[0] = 0
            return 0.0, W, Wa, 0
        if vv_new >= vv:
            break  # no more progress: the rounding floor is reached
        v[:] = v_new
    hints[a] = hint_a
    hints[b] = hint_b
    simplex[0] = n
    for i in range(n):
        simplex[1 + 2 * i] = ids[i, 0]
        simplex[2 + 2 * i] = ids[i, 1]
    # The lower bound, not |v| (an upper bound): stopping early must not over-state clearance.
    return max(lower - radius_a - radius_b, 0.0), W, Wa, n


@jit()
def _cached_simplex(
    vertices: np.ndarray,
    R_a: np.ndarray,
    p_a: np.ndarray,
    R_b: np.ndarray,
    p_b: np.ndarray,
    simplex: np.ndarray,
    W: np.ndarray,
    Wa: np.ndarray,
    ids: np.ndarray,
    keep: np.ndarray,
    best_keep: np.ndarray,
    trial: np.ndarray,
    v: np.ndarray,
) -> int:
    """The cached simplex's vertices at the new poses in W, Wa, ids, reduced to the feature
    closest to the origin (v); returns its size, 0 when there is none or it holds the origin."""
    n = simplex[0]
    for i in range(n):
        ids[i, 0], ids[i, 1] = simplex[1 + 2 * i], simplex[2 + 2 * i]
        Wa[i] = 0.0
        _add_vertex(vertices, ids[i, 0], R_a, p_a, Wa[i], 1.0)
        W[i] = Wa[i]
        _add_vertex(vertices, ids[i, 1], R_b, p_b, W[i], -1.0)
    if n == 0:
        return 0
    n = _closest_on_simplex(W, Wa, ids, n, keep, best_keep, trial, v)
    return n if _dot(v, v) > 1e-24 else 0
