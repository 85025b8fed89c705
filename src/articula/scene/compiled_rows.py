"""The reactive controllers' hot path in one compiled call: forward kinematics, the
end-effector Jacobian, and every link-obstacle cell and checked link pair within an influence
distance with its distance, witness points and gradient in joint space.

The same quantities as Scene.witnesses_within, RobotModel.directional_gradients and
RobotModel.jacobian, on a CompiledClearance (revolute chains, convex shapes, obstacles that do
not move): through Pinocchio and coal they are a few dozen Python-level calls a period.
GJK gives no penetration depth, so a pair that overlaps is reported and the caller falls back
to coal for that period.
"""

from __future__ import annotations

import math

import numpy as np

from articula.numba_cache import jit
from articula.scene.compiled_bundles import named_inputs
from articula.scene.compiled_clearance import CompiledClearance
from articula.scene.compiled_poses import (
    _capsule_gaps,
    _ee_pose,
    _joint_poses,
    _shape_poses,
)
from articula.scene.gjk import gjk_witnesses


def clearance_rows(
    compiled: CompiledClearance, q: np.ndarray, influence: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """At q [rad]: (end-effector position [m], rotation (3×3), Jacobian (6 × nq, world axes,
    linear rows first), distances d [m] of the cells and link pairs closer than `influence`
    [m], their gradients ∂d/∂q (rows × nq), which rows are link pairs); None when a pair
    within `influence` overlaps.

    Rows come in Scene's order: (link, obstacle) cells row-major, then the checked link
    pairs; each row is the closest of its cell's shape pairs, ∇d = n·(J_a − J_b) at the
    witness points, n the unit vector from b's closest point to a's (b: the obstacle or the
    pair's second link). A row no joint moves is left out.

    Args:
        compiled: the scene's arrays (its obstacles do not move).
        q: joint positions, shape (nq,) [rad].
        influence: distance below which a cell or link pair gives a row [m].

    Returns:
        (ee position, shape (3,) [m]; ee rotation, shape (3, 3); Jacobian, shape (6, nq),
        linear rows [m/rad] then angular rows; distances, shape (rows,) [m]; gradients ∂d/∂q,
        shape (rows, nq) [m/rad]; link-pair flags, shape (rows,) bool), or None on an overlap.
    """
    out = _rows(q, compiled.inputs(), compiled.cells, influence, q.size)
    return None if out[6] else out[:6]


@jit()
def _lever(oR, op, chain, joint, point, normal, sign, row):
    """row += sign · n·(∂point/∂q): for each revolute joint k above `joint`, the world axis
    a_k and origin o_k give n·(a_k × (p − o_k)) = a_k · ((p − o_k) × n)."""
    axes, q_index, parents = chain.axes, chain.q_index, chain.parents
    k = joint
    while k != 0:
        rx, ry, rz = point[0] - op[k, 0], point[1] - op[k, 1], point[2] - op[k, 2]
        cx = ry * normal[2] - rz * normal[1]
        cy = rz * normal[0] - rx * normal[2]
        cz = rx * normal[1] - ry * normal[0]
        value = 0.0
        for i in range(3):
            axis_i = oR[k, i, 0] * axes[k, 0] + oR[k, i, 1] * axes[k, 1] + oR[k, i, 2] * axes[k, 2]
            value += axis_i * (cx if i == 0 else (cy if i == 1 else cz))
        row[q_index[k]] += sign * value
        k = parents[k]


@jit()
def _jacobian(oR, op, chain, joint, point, nq):
    """The 6 × nq world-axes Jacobian of a point moving with `joint`: (a_k × (p − o_k); a_k)."""
    axes, q_index, parents = chain.axes, chain.q_index, chain.parents
    J = np.zeros((6, nq))
    k = joint
    while k != 0:
        a = oR[k] @ axes[k]
        r = point - op[k]
        col = q_index[k]
        J[0, col] = a[1] * r[2] - a[2] * r[1]
        J[1, col] = a[2] * r[0] - a[0] * r[2]
        J[2, col] = a[0] * r[1] - a[1] * r[0]
        J[3:, col] = a
        k = parents[k]
    return J


@jit()
def _rows(q, packed_inputs, cells, influence, nq):
    """clearance_rows in one compiled call; the last item flags an overlap."""
    inputs = named_inputs(packed_inputs)
    chain, shapes, pairs = inputs.chain, inputs.shapes, inputs.pairs
    oR, op = _joint_poses(q, chain)
    ee, ee_R = _ee_pose(oR, op, chain)
    J = _jacobian(oR, op, chain, chain.ee_joint, ee, nq)
    world_R, world_p, ends = _shape_poses(oR, op, shapes, pairs)
    lower = _capsule_gaps(ends, shapes.capsule_r, pairs)
    best = np.full(cells, np.inf)
    on_a = np.zeros((cells, 3))
    on_b = np.zeros((cells, 3))
    shape_a = np.zeros(cells, dtype=np.int64)
    shape_b = np.zeros(cells, dtype=np.int64)
    kind = np.zeros(cells, dtype=np.int64)
    point_a = np.empty(3)
    point_b = np.empty(3)
    for k in range(pairs.shape[0]):
        cell = pairs[k, 4]
        if lower[k] >= influence or lower[k] >= best[cell]:
            continue  # the capsules already rule it out
        a, b = pairs[k, 0], pairs[k, 1]
        d = gjk_witnesses(
            shapes.vertices,
            shapes.neighbours,
            shapes.offsets,
            inputs.scratch.hints,
            a,
            world_R[a],
            world_p[a],
            shapes.radii[a],
            b,
            world_R[b],
            world_p[b],
            shapes.radii[b],
            inputs.scratch.simplices[pairs[k, 2]],
            point_a,
            point_b,
        )
        if d <= 0.0:
            return ee, ee_R, J, np.zeros(0), np.zeros((0, nq)), np.zeros(0, np.bool_), True
        if d < best[cell]:
            best[cell] = d
            on_a[cell] = point_a
            on_b[cell] = point_b
            shape_a[cell], shape_b[cell], kind[cell] = a, b, pairs[k, 3]
    near = np.flatnonzero(best < influence)
    distance = np.empty(near.size)
    gradient = np.zeros((near.size, nq))
    self_pair = np.empty(near.size, dtype=np.bool_)
    normal = np.empty(3)
    count = 0
    for cell in near:
        gap = on_a[cell] - on_b[cell]
        length = math.sqrt(gap @ gap)
        if length < 1e-9:
            continue  # no direction to move along
        for i in range(3):
            normal[i] = gap[i] / length
        row = gradient[count]
        _lever(oR, op, chain, shapes.joint[shape_a[cell]], on_a[cell], normal, 1.0, row)
        _lever(oR, op, chain, shapes.joint[shape_b[cell]], on_b[cell], normal, -1.0, row)
        moving = False
        for i in range(nq):
            if row[i] != 0.0:
                moving = True
        if moving:  # a world-fixed pair: no joint changes its d, so no row can help
            distance[count] = best[cell]
            self_pair[count] = kind[cell] == 1
            count += 1
        else:
            row[:] = 0.0
    return ee, ee_R, J, distance[:count], gradient[:count], self_pair[:count], False
