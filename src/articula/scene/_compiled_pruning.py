"""Pruning over a box of joint angles, compiled: the pairs that can hold the smallest
link-obstacle distance anywhere in the box (CompiledClearance.near_pairs)."""

from __future__ import annotations

import math

import numpy as np

from articula.numba_cache import jit
from articula.scene.compiled_bundles import named_inputs
from articula.scene.compiled_poses import _apply, _capsule_gaps, _joint_poses, _shape_poses
from articula.scene.gjk import gjk_distance


@jit()
def _pair_bounds(q, chain, shapes, pairs):
    """(lower, upper) bounds of every pair's distance at q: its capsules' gap, and the gap
    between the balls of radius r around one core point of each shape; and the shapes' world
    rotations and positions at q."""
    oR, op = _joint_poses(q, chain)
    world_R, world_p, ends = _shape_poses(oR, op, shapes, pairs)
    vertices, starts, radii = shapes.vertices, shapes.starts, shapes.radii
    upper = np.empty(pairs.shape[0])
    point_a = np.empty(3)
    point_b = np.empty(3)
    for k in range(pairs.shape[0]):
        a, b = pairs[k, 0], pairs[k, 1]
        _apply(world_R[a], world_p[a], vertices[starts[a]], point_a)
        _apply(world_R[b], world_p[b], vertices[starts[b]], point_b)
        gap = point_a - point_b
        upper[k] = math.sqrt(gap @ gap) - radii[a] - radii[b]
    return _capsule_gaps(ends, shapes.capsule_r, pairs), upper, world_R, world_p


@jit()
def _near_pairs(lower, upper, sweep, static_min, packed_inputs):
    """CompiledClearance.near_pairs in one compiled call (it runs once per control period)."""
    inputs = named_inputs(packed_inputs)
    chain, shapes, pairs = inputs.chain, inputs.shapes, inputs.pairs
    centre = (lower + upper) / 2.0
    delta = np.sum(sweep * (upper - lower)) / 2.0
    below, above, world_R, world_p = _pair_bounds(centre, chain, shapes, pairs)
    ceiling = static_min
    nearest = -1  # the obstacle pair of the smallest lower bound
    for k in range(pairs.shape[0]):
        if pairs[k, 3] == 0 and above[k] < ceiling:
            ceiling = above[k]
        if pairs[k, 3] == 0 and (nearest < 0 or below[k] < below[nearest]):
            nearest = k
    if nearest >= 0:  # its exact distance at the centre bounds the minimum there too
        a, b = pairs[nearest, 0], pairs[nearest, 1]
        scratch = inputs.scratch  # copies: the evaluations' warm starts stay as they were
        exact = gjk_distance(shapes.vertices, shapes.neighbours, shapes.offsets,
                             scratch.hints.copy(), a, world_R[a], world_p[a], shapes.radii[a],
                             b, world_R[b], world_p[b], shapes.radii[b],
                             scratch.simplices[pairs[nearest, 2]].copy())  # fmt: skip
        ceiling = min(ceiling, exact)
    ceiling += 2.0 * delta
    keep = np.array([pairs[k, 3] != 0 or below[k] <= ceiling for k in range(pairs.shape[0])])
    return pairs[keep]
