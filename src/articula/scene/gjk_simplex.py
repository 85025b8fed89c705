"""The simplex step of GJK (scene/gjk.py): the point of a simplex of up to four points of
A − B closest to the origin, and the simplex reduced to the feature it lies on (Ericson,
Real-Time Collision Detection, 5.1.5 and 9.5). Scalar arithmetic only: this runs in GJK's
inner loop, where allocations dominate."""

from __future__ import annotations

import numpy as np

from articula.numba_cache import jit


@jit()
def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """a · b for 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


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
    the vertices of the feature it lies on (Ericson, Real-Time Collision Detection, 5.1.5)."""
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
def _reduce(W: np.ndarray, Wa: np.ndarray, ids: np.ndarray, n: int, keep: np.ndarray) -> int:
    """Keep only the flagged simplex vertices (their A supports and vertex ids alike), packed
    at the front; returns their count."""
    m = 0
    for i in range(n):
        if keep[i]:
            _move(W, Wa, ids, i, m)
            m += 1
    return m


@jit()
def _move(W: np.ndarray, Wa: np.ndarray, ids: np.ndarray, i: int, m: int) -> None:
    """Simplex vertex i (with its A support and vertex ids) copied to slot m."""
    for k in range(3):
        W[m, k] = W[i, k]
        Wa[m, k] = Wa[i, k]
    ids[m, 0] = ids[i, 0]
    ids[m, 1] = ids[i, 1]


@jit()
def _beyond_face(W: np.ndarray, ia: int, ib: int, ic: int, iopp: int) -> bool:
    """True if the origin and W[iopp] are on opposite sides of face (ia, ib, ic), or the
    tetrahedron is flat there (then every face is a candidate)."""
    abx, aby, abz = W[ib, 0] - W[ia, 0], W[ib, 1] - W[ia, 1], W[ib, 2] - W[ia, 2]
    acx, acy, acz = W[ic, 0] - W[ia, 0], W[ic, 1] - W[ia, 1], W[ic, 2] - W[ia, 2]
    nx, ny, nz = aby * acz - abz * acy, abz * acx - abx * acz, abx * acy - aby * acx
    side_origin = -(nx * W[ia, 0] + ny * W[ia, 1] + nz * W[ia, 2])
    side_opposite = (
        nx * (W[iopp, 0] - W[ia, 0]) + ny * (W[iopp, 1] - W[ia, 1]) + nz * (W[iopp, 2] - W[ia, 2])
    )
    flat = abs(side_opposite) <= 1e-14 * max(nx * nx + ny * ny + nz * nz, 1e-300)
    return flat or side_origin * side_opposite < 0.0


@jit()
def _closest_on_simplex(
    W: np.ndarray,
    Wa: np.ndarray,
    ids: np.ndarray,
    n: int,
    keep: np.ndarray,
    best_keep: np.ndarray,
    trial: np.ndarray,
    out: np.ndarray,
) -> int:
    """out = the closest point to the origin on the simplex W[:n] (Wa: the A supports of its
    vertices, ids: their vertex indices in A and B, reduced alike); returns the reduced
    simplex size, 4 meaning the origin is inside the tetrahedron (the shapes overlap)."""
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
            _move(W, Wa, ids, 1, 0)
            _point_on(W, 0, 0, 0.0, out)
            return 1
        _point_on(W, 0, 1, t, out)
        return 2
    if n == 3:
        _closest_on_triangle(W, 0, 1, 2, keep, out)
        return _reduce(W, Wa, ids, 3, keep)
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
    return _reduce(W, Wa, ids, 4, keep)
