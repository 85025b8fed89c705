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

_MAX_ITERATIONS = 64
_RELATIVE_TOLERANCE = 1e-12  # stop when |v|² − v·w <= tol·|v|² (Gilbert et al. 1988)


@jit()
def _dot(a: np.ndarray, b: np.ndarray) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit()
def _support(
    vertices: np.ndarray, neighbours: np.ndarray, offsets: np.ndarray, hint: int,
    R: np.ndarray, p: np.ndarray, dx: float, dy: float, dz: float, out: np.ndarray, sign: float,
) -> int:  # fmt: skip
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
    x, y, z = vertices[k, 0], vertices[k, 1], vertices[k, 2]
    for i in range(3):
        out[i] += sign * (R[i, 0] * x + R[i, 1] * y + R[i, 2] * z + p[i])
    return k


@jit()
def _point_on(W: np.ndarray, i: int, j: int, t: float, out: np.ndarray) -> None:
    """out = W[i] + t (W[j] − W[i])."""
    for k in range(3):
        out[k] = W[i, k] + t * (W[j, k] - W[i, k])


@jit()
def _closest_on_triangle(
    W: np.ndarray, ia: int, ib: int, ic: int, keep: np.ndarray, out: np.ndarray
) -> None:
    """out = the closest point to the origin on triangle (W[ia], W[ib], W[ic]); `keep` flags
    the vertices of the feature it lies on (Ericson, Real-Time Collision Detection, 5.1.5).
    Scalar arithmetic only: this runs in GJK's inner loop, where allocations dominate."""
    abx, aby, abz = W[ib, 0] - W[ia, 0], W[ib, 1] - W[ia, 1], W[ib, 2] - W[ia, 2]
    acx, acy, acz = W[ic, 0] - W[ia, 0], W[ic, 1] - W[ia, 1], W[ic, 2] - W[ia, 2]
    d1 = -(abx * W[ia, 0] + aby * W[ia, 1] + abz * W[ia, 2])
    d2 = -(acx * W[ia, 0] + acy * W[ia, 1] + acz * W[ia, 2])
    keep[:] = False
    if d1 <= 0.0 and d2 <= 0.0:
        keep[ia] = True
        _point_on(W, ia, ia, 0.0, out)
        return
    d3 = -(abx * W[ib, 0] + aby * W[ib, 1] + abz * W[ib, 2])
    d4 = -(acx * W[ib, 0] + acy * W[ib, 1] + acz * W[ib, 2])
    if d3 >= 0.0 and d4 <= d3:
        keep[ib] = True
        _point_on(W, ib, ib, 0.0, out)
        return
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        keep[ia] = True
        keep[ib] = True
        _point_on(W, ia, ib, d1 / (d1 - d3) if d1 > d3 else 0.0, out)
        return
    d5 = -(abx * W[ic, 0] + aby * W[ic, 1] + abz * W[ic, 2])
    d6 = -(acx * W[ic, 0] + acy * W[ic, 1] + acz * W[ic, 2])
    if d6 >= 0.0 and d5 <= d6:
        keep[ic] = True
        _point_on(W, ic, ic, 0.0, out)
        return
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        keep[ia] = True
        keep[ic] = True
        _point_on(W, ia, ic, d2 / (d2 - d6) if d2 > d6 else 0.0, out)
        return
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        keep[ib] = True
        keep[ic] = True
        span = (d4 - d3) + (d5 - d6)
        _point_on(W, ib, ic, (d4 - d3) / span if span > 0.0 else 0.0, out)
        return
    total = va + vb + vc
    if total <= 0.0:  # a degenerate (flat) triangle: its first edge is as close as it gets
        keep[ia] = True
        keep[ib] = True
        t = d1 / (d1 - d3) if d1 > d3 else 0.0
        _point_on(W, ia, ib, min(max(t, 0.0), 1.0), out)
        return
    keep[ia] = True
    keep[ib] = True
    keep[ic] = True
    v, w = vb / total, vc / total
    for k in range(3):
        out[k] = W[ia, k] + v * (W[ib, k] - W[ia, k]) + w * (W[ic, k] - W[ia, k])


@jit()
def _reduce(W: np.ndarray, Wa: np.ndarray, n: int, keep: np.ndarray) -> int:
    """Keep only the flagged simplex vertices (and their A supports), packed at the front;
    returns their count."""
    m = 0
    for i in range(n):
        if keep[i]:
            for k in range(3):
                W[m, k] = W[i, k]
                Wa[m, k] = Wa[i, k]
            m += 1
    return m


@jit()
def _beyond_face(W: np.ndarray, ia: int, ib: int, ic: int, iopp: int) -> bool:
    """True if the origin and W[iopp] are on opposite sides of face (ia, ib, ic), or the
    tetrahedron is flat there (then every face is a candidate)."""
    abx, aby, abz = W[ib, 0] - W[ia, 0], W[ib, 1] - W[ia, 1], W[ib, 2] - W[ia, 2]
    acx, acy, acz = W[ic, 0] - W[ia, 0], W[ic, 1] - W[ia, 1], W[ic, 2] - W[ia, 2]
    nx, ny, nz = aby * acz - abz * acy, abz * acx - abx * acz, abx * acy - aby * acx
    side_origin = -(nx * W[ia, 0] + ny * W[ia, 1] + nz * W[ia, 2])
    side_opposite = (nx * (W[iopp, 0] - W[ia, 0]) + ny * (W[iopp, 1] - W[ia, 1])
                     + nz * (W[iopp, 2] - W[ia, 2]))  # fmt: skip
    flat = abs(side_opposite) <= 1e-14 * max(nx * nx + ny * ny + nz * nz, 1e-300)
    return flat or side_origin * side_opposite < 0.0


@jit()
def _closest_on_simplex(
    W: np.ndarray, Wa: np.ndarray, n: int, keep: np.ndarray, best_keep: np.ndarray,
    trial: np.ndarray, out: np.ndarray,
) -> int:  # fmt: skip
    """out = the closest point to the origin on the simplex W[:n] (Wa: the A supports of its
    vertices, reduced alike); returns the reduced simplex size, 4 meaning the origin is inside
    the tetrahedron (the shapes overlap)."""
    if n == 1:
        _point_on(W, 0, 0, 0.0, out)
        return 1
    if n == 2:
        abx, aby, abz = W[1, 0] - W[0, 0], W[1, 1] - W[0, 1], W[1, 2] - W[0, 2]
        denom = abx * abx + aby * aby + abz * abz
        t = -(W[0, 0] * abx + W[0, 1] * aby + W[0, 2] * abz) / denom if denom > 0.0 else 0.0
        if t <= 0.0:
            _point_on(W, 0, 0, 0.0, out)
            return 1
        if t >= 1.0:
            for k in range(3):
                W[0, k] = W[1, k]
                Wa[0, k] = Wa[1, k]
            _point_on(W, 0, 0, 0.0, out)
            return 1
        _point_on(W, 0, 1, t, out)
        return 2
    if n == 3:
        _closest_on_triangle(W, 0, 1, 2, keep, out)
        return _reduce(W, Wa, 3, keep)
    best = np.inf
    any_outside = False
    for f in range(4):  # faces (0,1,2|3), (0,2,3|1), (0,3,1|2), (1,3,2|0)
        if f == 0:
            ia, ib, ic, iopp = 0, 1, 2, 3
        elif f == 1:
            ia, ib, ic, iopp = 0, 2, 3, 1
        elif f == 2:
            ia, ib, ic, iopp = 0, 3, 1, 2
        else:
            ia, ib, ic, iopp = 1, 3, 2, 0
        if _beyond_face(W, ia, ib, ic, iopp):
            any_outside = True
            _closest_on_triangle(W, ia, ib, ic, keep, trial)
            dist = _dot(trial, trial)
            if dist < best:
                best = dist
                out[:] = trial
                best_keep[:] = keep
    if not any_outside:
        return 4
    keep[:] = best_keep
    return _reduce(W, Wa, 4, keep)


@jit()
def gjk_distance(
    vertices: np.ndarray, neighbours: np.ndarray, offsets: np.ndarray, hints: np.ndarray,
    a: int, R_a: np.ndarray, p_a: np.ndarray, radius_a: float,
    b: int, R_b: np.ndarray, p_b: np.ndarray, radius_b: float, guess: np.ndarray,
) -> float:  # fmt: skip
    """Distance [m] between two posed cores a and b swept by their radii; 0 when they overlap.

    `vertices` holds every core; `neighbours[offsets[k]:offsets[k + 1]]` are the vertices
    joined to vertex k by a hull edge; `hints[a]` is a vertex of core a where its support
    search starts, updated to the last support found (successive queries are close, so the
    climb is short; the answer does not depend on the hint). `guess` is the last closest
    point of A − B for this pair (zero: none), the first search direction, updated on return:
    close queries then converge in one or two iterations.
    """
    return _gjk(vertices, neighbours, offsets, hints, a, R_a, p_a, radius_a, b, R_b, p_b,
                radius_b, guess)[0]  # fmt: skip


@jit()
def gjk_witnesses(
    vertices: np.ndarray, neighbours: np.ndarray, offsets: np.ndarray, hints: np.ndarray,
    a: int, R_a: np.ndarray, p_a: np.ndarray, radius_a: float,
    b: int, R_b: np.ndarray, p_b: np.ndarray, radius_b: float, guess: np.ndarray,
    on_a: np.ndarray, on_b: np.ndarray,
) -> float:  # fmt: skip
    """gjk_distance, and the closest points of the two shapes' surfaces [m, world] written to
    on_a and on_b; when the shapes overlap (0 returned) on_a and on_b are left as they were.

    The points come from the final simplex: the closest point of A − B is Σ λ_i w_i with
    w_i = a_i − b_i, so Σ λ_i a_i is a closest point of core A and that minus the closest
    point of A − B one of core B; each moves by its radius along the normal to the surface.
    """
    d, W, Wa, n = _gjk(vertices, neighbours, offsets, hints, a, R_a, p_a, radius_a, b, R_b,
                       p_b, radius_b, guess)  # fmt: skip
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
    vertices: np.ndarray, neighbours: np.ndarray, offsets: np.ndarray, hints: np.ndarray,
    a: int, R_a: np.ndarray, p_a: np.ndarray, radius_a: float,
    b: int, R_b: np.ndarray, p_b: np.ndarray, radius_b: float, guess: np.ndarray,
) -> tuple[float, np.ndarray, np.ndarray, int]:  # fmt: skip
    """GJK itself: (distance, the final simplex W of A − B, the A supports Wa of its vertices,
    its size n; 0 when the shapes overlap)."""
    # Two allocations, the rest views: this runs a few hundred times per control period.
    scratch = np.empty((13, 3))
    W, Wa = scratch[0:4], scratch[4:8]
    trial, w, support_a, v, v_new = scratch[8], scratch[9], scratch[10], scratch[11], scratch[12]
    flags = np.zeros(8, dtype=np.bool_)
    keep, best_keep = flags[0:4], flags[4:8]
    hint_a, hint_b = hints[a], hints[b]
    lower = 0.0
    # Start from a point of the Minkowski difference: the support against the last answer,
    # or along the centres' offset.
    dx, dy, dz = -guess[0], -guess[1], -guess[2]
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        dx, dy, dz = p_b[0] - p_a[0], p_b[1] - p_a[1], p_b[2] - p_a[2]
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        dx = 1.0
    n = 0
    for iteration in range(_MAX_ITERATIONS + 1):
        # w = s_A(d) − s_B(−d), the support of A − B along d (first d, then −v).
        support_a[0] = 0.0
        support_a[1] = 0.0
        support_a[2] = 0.0
        hint_a = _support(vertices, neighbours, offsets, hint_a, R_a, p_a, dx, dy, dz,
                          support_a, 1.0)  # fmt: skip
        w[:] = support_a
        hint_b = _support(vertices, neighbours, offsets, hint_b, R_b, p_b, -dx, -dy, -dz, w,
                          -1.0)  # fmt: skip
        if iteration == 0:
            v[:] = w
            W[0] = w
            Wa[0] = support_a
            n = 1
        else:
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
            n += 1
            n = _closest_on_simplex(W, Wa, n, keep, best_keep, trial, v_new)
            vv_new = _dot(v_new, v_new)
            if n == 4 or vv_new <= 1e-24:
                hints[a] = hint_a
                hints[b] = hint_b
                guess[:] = 0.0
                return 0.0, W, Wa, 0
            if vv_new >= vv:
                break  # no more progress: the rounding floor is reached
            v[:] = v_new
        dx, dy, dz = -v[0], -v[1], -v[2]
    hints[a] = hint_a
    hints[b] = hint_b
    guess[:] = v
    # The lower bound, not |v| (an upper bound): stopping early must not over-state clearance.
    return max(lower - radius_a - radius_b, 0.0), W, Wa, n
