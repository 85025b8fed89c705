"""Compiled kinematics of the clearance path: joint and shape poses of a revolute chain, and
the capsule broad phase's segment distances (numba, scalar arithmetic: no BLAS calls)."""

from __future__ import annotations

import math

import numpy as np

from articula.numba_cache import jit


@jit()
def _compose(
    R1: np.ndarray, p1: np.ndarray, R2: np.ndarray, p2: np.ndarray, R: np.ndarray, p: np.ndarray
) -> None:
    """(R, p) = (R1, p1) ∘ (R2, p2): R = R1 R2, p = p1 + R1 p2 (3×3 by hand: no BLAS call)."""
    for i in range(3):
        p[i] = p1[i] + R1[i, 0] * p2[0] + R1[i, 1] * p2[1] + R1[i, 2] * p2[2]
        for k in range(3):
            R[i, k] = R1[i, 0] * R2[0, k] + R1[i, 1] * R2[1, k] + R1[i, 2] * R2[2, k]


@jit()
def _rotate_about(R: np.ndarray, axis: np.ndarray, angle: float, out: np.ndarray) -> None:
    """out = R · Rot(axis, angle) (Rodrigues), axis a unit vector; about a coordinate axis
    only two columns mix (most URDF joints: a third of the arithmetic)."""
    c, s = math.cos(angle), math.sin(angle)
    x, y, z = axis[0], axis[1], axis[2]
    if x == 0.0 and y == 0.0 and z == 1.0:
        _turn_columns(R, 0, 1, 2, c, s, out)
    elif y == 0.0 and z == 0.0 and x == 1.0:
        _turn_columns(R, 1, 2, 0, c, s, out)
    elif z == 0.0 and x == 0.0 and y == 1.0:
        _turn_columns(R, 2, 0, 1, c, s, out)
    else:
        C = 1.0 - c
        r00, r01, r02 = c + x * x * C, x * y * C - z * s, x * z * C + y * s
        r10, r11, r12 = y * x * C + z * s, c + y * y * C, y * z * C - x * s
        r20, r21, r22 = z * x * C - y * s, z * y * C + x * s, c + z * z * C
        for i in range(3):
            a, b, d = R[i, 0], R[i, 1], R[i, 2]
            out[i, 0] = a * r00 + b * r10 + d * r20
            out[i, 1] = a * r01 + b * r11 + d * r21
            out[i, 2] = a * r02 + b * r12 + d * r22


@jit()
def _turn_columns(R, i, j, k, c, s, out):
    """out = R · Rot(e_k, angle) for the coordinate axis e_k, (i, j, k) a cyclic order:
    columns i and j turn by (c, s) = (cos, sin) of the angle, column k stays."""
    for m in range(3):
        a, b = R[m, i], R[m, j]
        out[m, i] = c * a + s * b
        out[m, j] = c * b - s * a
        out[m, k] = R[m, k]


@jit()
def _apply(R: np.ndarray, p: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """out = R x + p."""
    for i in range(3):
        out[i] = R[i, 0] * x[0] + R[i, 1] * x[1] + R[i, 2] * x[2] + p[i]


@jit()
def _segment_distance(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> float:
    """Distance between segments [p1, q1] and [p2, q2] (Ericson, Sect. 5.1.9), in scalars."""
    d1x, d1y, d1z = q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]
    d2x, d2y, d2z = q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]
    rx, ry, rz = p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2]
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    s = 0.0
    t = 0.0
    if a > 1e-18 or e > 1e-18:
        if a <= 1e-18:
            t = min(max(f / e, 0.0), 1.0)
        else:
            c = d1x * rx + d1y * ry + d1z * rz
            if e <= 1e-18:
                s = min(max(-c / a, 0.0), 1.0)
            else:
                b = d1x * d2x + d1y * d2y + d1z * d2z
                denom = a * e - b * b
                s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > 0.0 else 0.0
                t = (b * s + f) / e
                if t < 0.0:
                    t, s = 0.0, min(max(-c / a, 0.0), 1.0)
                elif t > 1.0:
                    t, s = 1.0, min(max((b - c) / a, 0.0), 1.0)
    gx = rx + d1x * s - d2x * t
    gy = ry + d1y * s - d2y * t
    gz = rz + d1z * s - d2z * t
    return np.sqrt(gx * gx + gy * gy + gz * gz)


@jit(inline="always")
def _joint_poses(q, chain):
    """World rotation and origin of every joint frame of `chain` (a Chain) at q (joint 0:
    the world)."""
    parents, joint_rot, joint_p, axes = chain.parents, chain.joint_rot, chain.joint_p, chain.axes
    nj = parents.size
    oR = np.empty((nj, 3, 3))
    op = np.empty((nj, 3))
    oR[0] = np.eye(3)
    op[0] = 0.0
    placed = np.empty((3, 3))
    for j in range(1, nj):
        parent = parents[j]
        _compose(oR[parent], op[parent], joint_rot[j], joint_p[j], placed, op[j])
        _rotate_about(placed, axes[j], q[chain.q_index[j]], oR[j])
    return oR, op


@jit(inline="always")
def _ee_pose(oR, op, chain):
    """The end effector's world position and rotation from its joint's pose and its
    placement (ee_rot, ee_p) in that joint's frame."""
    ee_joint, ee_p, ee_rot = chain.ee_joint, chain.ee_p, chain.ee_rot
    ee = np.empty(3)
    _apply(oR[ee_joint], op[ee_joint], ee_p, ee)
    ee_R = np.empty((3, 3))
    _compose(oR[ee_joint], op[ee_joint], ee_rot, ee_p, ee_R, np.empty(3))
    return ee, ee_R


@jit(inline="always")
def _shape_poses(oR, op, shapes, pairs, ends_too=True):
    """World pose of every shape of `pairs` and (with ends_too; else unset, see _place_ends)
    the ends of its bounding capsule's segment (the other shapes' rows are left unset: a far
    obstacle costs nothing here)."""
    ns = shapes.joint.size
    world_R = np.empty((ns, 3, 3))
    world_p = np.empty((ns, 3))
    ends = np.empty((ns, 2, 3))
    done = np.zeros(ns, dtype=np.bool_)
    for k in range(pairs.shape[0]):
        for s in (pairs[k, 0], pairs[k, 1]):
            if not done[s]:
                done[s] = True
                j = shapes.joint[s]
                _compose(oR[j], op[j], shapes.rot[s], shapes.p[s], world_R[s], world_p[s])
                if ends_too:
                    _place_ends(s, world_R, world_p, shapes.capsule_a, shapes.capsule_b, ends)
    return world_R, world_p, ends


@jit()
def _place_ends(s, world_R, world_p, capsule_a, capsule_b, ends):
    """ends[s] = the world ends of shape s's bounding capsule segment (the two arrays, not
    Shapes: this runs per pair, and each array passed costs two atomic reference counts)."""
    _apply(world_R[s], world_p[s], capsule_a[s], ends[s, 0])
    _apply(world_R[s], world_p[s], capsule_b[s], ends[s, 1])


@jit()
def _capsule_gaps(ends, capsule_r, pairs):
    """Capsule-capsule distance of every pair: a lower bound of its exact distance."""
    lower = np.empty(pairs.shape[0])
    for k in range(pairs.shape[0]):
        a, b = pairs[k, 0], pairs[k, 1]
        gap = _segment_distance(ends[a, 0], ends[a, 1], ends[b, 0], ends[b, 1])
        lower[k] = gap - capsule_r[a] - capsule_r[b]
    return lower


@jit()
def _moved(memory, row, at, world_R, world_p, s, extent):
    """A bound [m] on how far any point within `extent` of shape s's origin moved from the
    pose (R0, p0) stored in memory[row, at:at + 12] (R0 row-major, then p0) to its pose now,
    (world_R[s], world_p[s]): |p − p0| + ||R − R0||₂ extent, ||R − R0||₂ = √(3 − tr(R0ᵀ R)).
    Indices, not views: a view costs two atomic reference counts, more than the arithmetic."""
    trace = 0.0
    for i in range(3):
        for k in range(3):
            trace += memory[row, at + 3 * i + k] * world_R[s, i, k]
    dx = world_p[s, 0] - memory[row, at + 9]
    dy = world_p[s, 1] - memory[row, at + 10]
    dz = world_p[s, 2] - memory[row, at + 11]
    return math.sqrt(dx * dx + dy * dy + dz * dz) + math.sqrt(max(3.0 - trace, 0.0)) * extent


@jit()
def _remembered_bound(memory, row, a, b, world_R, world_p, extents, joint):
    """The last lower bound of a pair (memory[row]: an exact distance or a capsule gap) less
    how far its shapes a and b moved since: a lower bound of its distance now (−inf before
    the first). A shape on joint 0 (an obstacle) has not moved: CompiledClearance.at charges
    an obstacle's motion to its pairs' memory when it puts it at a new pose. Shapes' extents
    and joints, not Shapes: this runs per pair (see _place_ends)."""
    if memory[row, 0] == -np.inf:
        return -np.inf
    bound = memory[row, 0] - _moved(memory, row, 1, world_R, world_p, a, extents[a])
    if joint[b] != 0:
        bound -= _moved(memory, row, 13, world_R, world_p, b, extents[b])
    return bound


@jit()
def _remember(memory, d, R_a, p_a, R_b, p_b):
    """Store a lower bound d [m] of a pair's distance and the poses of its shapes it holds at."""
    memory[0] = d
    memory[1:10] = R_a.ravel()
    memory[10:13] = p_a
    memory[13:22] = R_b.ravel()
    memory[22:25] = p_b
