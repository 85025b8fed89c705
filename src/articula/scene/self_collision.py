"""Which link pairs a self-collision check must look at: an allowed-collision matrix.

Built the way MoveIt's setup assistant builds its matrix: a pair is skipped when its links are
adjacent in the kinematic tree (they touch at their joint by design), when over random
configurations within the joint limits it never comes closer than a margin (it cannot collide)
or always overlaps (their hulls overlap whatever the joints do, so a check would only ever
say "colliding"), or when the scene file allows it. Every other pair is checked.

The work is bounded: a bounding sphere per link rules out, in one array operation over every
sample, the pairs that are never within the margin; the exact distances that remain are
capped at MAX_QUERIES, and a pair still undecided then is checked (the safe side). The matrix
is a property of the robot, so it is kept on disk (disk_cache) under a hash of everything it
depends on, and a second build of the same robot reads it back.
"""

from __future__ import annotations

import hashlib
import itertools
import json
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from articula.disk_cache import keep, read_cached
from articula.robots.model import RobotModel
from articula.scene.pairs import link_pairs
from articula.scene.scene import Scene

Reason = Literal["adjacent", "never close", "always touching", "allowed"]
SAMPLES = 1000  # random configurations; MoveIt's assistant defaults to 10,000 collision checks
MARGIN = 0.02  # [m] a pair that never comes closer than this over the samples is skipped
MAX_QUERIES = 200_000  # exact pair distances one matrix may compute; undecided pairs are checked
_FORMAT = "self-collision/2"  # part of the cache key: a change of the algorithm re-computes
_CHUNK = 4096  # pairs whose sphere bounds are taken in one array operation


@dataclass(frozen=True)
class SelfCollisionMatrix:
    """The link pairs to check, and each skipped pair with why it was skipped.

    Attributes:
        checked: the link pairs (a, b) by name whose distance a self-collision check takes.
        skipped: every other pair, with its reason: "adjacent", "never close",
            "always touching" or "allowed".
    """

    checked: tuple[tuple[str, str], ...]
    skipped: dict[tuple[str, str], Reason]


def self_collision_matrix(
    robot: RobotModel,
    allow_pairs: Sequence[Sequence[str]] = (),
    samples: int = SAMPLES,
    margin: float = MARGIN,
    seed: int = 0,
) -> SelfCollisionMatrix:
    """The allowed-collision matrix of `robot`, read from the disk cache when it was made before.

    Args:
        robot: the arm; pairs are between its links with collision shapes.
        allow_pairs: [a, b] link name pairs never to check (a gripper's fingers, say).
        samples: random configurations, uniform within the joint limits (a continuous joint
            over one turn).
        margin: [m] a pair never closer than this over the samples is skipped.
        seed: seeds the samples (the matrix is a property of the robot: keep it fixed).

    Returns:
        The pairs to check, in link order, and the skipped ones with their reason.
    """
    names = [link.name for link in robot.links]
    allowed = [(names[a], names[b]) for a, b in link_pairs(allow_pairs, names, "allow_pairs")]
    key = _cache_key(robot, allowed, samples, margin, seed)
    cached = _read(key, names)
    if cached is not None:
        return cached
    skipped: dict[tuple[str, str], Reason] = dict.fromkeys(allowed, "allowed")
    joint = {link.name: robot.model.frames[link.frame_id].parentJoint for link in robot.links}
    parents = robot.model.parents
    candidates = []
    for a, b in itertools.combinations(range(len(names)), 2):
        if (names[a], names[b]) in skipped:
            continue
        ja, jb = joint[names[a]], joint[names[b]]
        if ja == jb or parents[ja] == jb or parents[jb] == ja:
            skipped[names[a], names[b]] = "adjacent"
        else:
            candidates.append((a, b))
    if candidates:
        rng = np.random.default_rng(seed)
        Q = rng.uniform(*robot.sample_range, (samples, robot.nq))
        near = _near_by_spheres(robot, Q, np.array(candidates), margin)
        skipped |= _decide(robot, Q, candidates, near, margin, names)
    checked = tuple(pair for pair in itertools.combinations(names, 2) if pair not in skipped)
    matrix = SelfCollisionMatrix(checked, skipped)
    _write(key, matrix)
    return matrix


def _decide(
    robot: RobotModel,
    Q: np.ndarray,
    candidates: list[tuple[int, int]],
    near: np.ndarray,
    margin: float,
    names: list[str],
) -> dict[tuple[str, str], Reason]:
    """The skipped candidates by exact distance at the samples their spheres come near; pairs
    left undecided when MAX_QUERIES runs out are checked (not returned)."""
    skipped: dict[tuple[str, str], Reason] = {}
    far_sample = ~near
    for k in np.flatnonzero(~near.any(axis=0)):
        skipped[names[candidates[k][0]], names[candidates[k][1]]] = "never close"
    open_pairs = np.flatnonzero(near.any(axis=0))
    # "always touching" needs every sample to overlap: spheres apart in one sample rule it out.
    may_touch = ~far_sample[:, open_pairs].any(axis=0)
    closest = np.full(open_pairs.size, np.inf)
    farthest = np.full(open_pairs.size, -np.inf)
    queries = 0
    undecided = np.ones(open_pairs.size, dtype=bool)
    pairs = [(names[candidates[k][0]], names[candidates[k][1]]) for k in open_pairs]
    scene = Scene(robot, [], self_pairs=pairs)
    for s in range(len(Q)):
        rows = np.flatnonzero(undecided & (near[s, open_pairs] | may_touch))
        if rows.size == 0:
            continue
        if queries + rows.size > MAX_QUERIES:
            break
        queries += rows.size
        d = scene.self_distances_of(Q[s], rows)
        closest[rows] = np.minimum(closest[rows], d)
        farthest[rows] = np.maximum(farthest[rows], d)
        # Decided: close once (then checked, unless it may always touch) and apart once.
        undecided[rows] = ~((closest[rows] <= margin) & ((farthest[rows] > 0) | ~may_touch[rows]))
    else:
        for r in np.flatnonzero(undecided):
            if closest[r] > margin:
                skipped[pairs[r]] = "never close"
            elif may_touch[r] and farthest[r] <= 0.0:
                skipped[pairs[r]] = "always touching"
    return skipped


def _near_by_spheres(
    robot: RobotModel, Q: np.ndarray, pairs: np.ndarray, margin: float
) -> np.ndarray:
    """(samples, pairs) True where the two links' bounding spheres come within `margin` [m],
    the only samples where their distance can."""
    centres, radii = _link_spheres(robot)
    world = np.empty((len(Q), len(robot.links), 3))
    for s, q in enumerate(Q):
        robot.forward(q)
        for i, link in enumerate(robot.links):
            placement = robot.data.oMf[link.frame_id]
            world[s, i] = placement.rotation @ centres[i] + placement.translation
    near = np.empty((len(Q), len(pairs)), dtype=bool)
    for start in range(0, len(pairs), _CHUNK):
        a, b = pairs[start : start + _CHUNK].T
        gap = np.linalg.norm(world[:, a] - world[:, b], axis=2) - radii[a] - radii[b]
        near[:, start : start + _CHUNK] = gap <= margin
    return near


def _link_spheres(robot: RobotModel) -> tuple[np.ndarray, np.ndarray]:
    """A sphere around each link's shapes: centres in the link frame (links, 3) [m], radii [m]."""
    centres, radii = [], []
    for link in robot.links:
        parts = []
        for shape, placement in zip(link.shapes, link.placements, strict=True):
            pose = placement @ shape.bound.pose
            parts.append((pose[:3, 3], 0.5 * shape.bound.length + shape.bound.radius))
        middle = np.mean([c for c, _ in parts], axis=0)
        centres.append(middle)
        radii.append(max(np.linalg.norm(c - middle) + r for c, r in parts))
    return np.array(centres), np.array(radii)


def _cache_key(
    robot: RobotModel,
    allowed: list[tuple[str, str]],
    samples: int,
    margin: float,
    seed: int,
) -> str:
    """The matrix's file name: a hash of the kinematics, the links' shapes and the settings."""
    model = robot.model
    digest = hashlib.sha256(_FORMAT.encode())
    for placement, joint in zip(model.jointPlacements, model.joints, strict=True):
        digest.update(joint.shortname().encode() + placement.homogeneous.tobytes())
    for values in (
        model.lowerPositionLimit,
        model.upperPositionLimit,
        robot.continuous,
        np.asarray(model.parents),
    ):
        digest.update(np.ascontiguousarray(values).tobytes())
    for link in robot.links:
        frame = model.frames[link.frame_id]
        digest.update(f"{link.name}/{frame.parentJoint}".encode())
        digest.update(frame.placement.homogeneous.tobytes())
        for shape, placement in zip(link.shapes, link.placements, strict=True):
            digest.update(shape.kind.encode() + shape.vertices.tobytes() + placement.tobytes())
    digest.update(repr((sorted(allowed), samples, margin, seed)).encode())
    return f"self_collision-{digest.hexdigest()}.json"


def _read(key: str, names: list[str]) -> SelfCollisionMatrix | None:
    """A matrix kept before, or None (absent, unreadable, or naming links the robot lacks)."""
    data = read_cached(key)
    if data is None:
        return None
    try:
        kept = json.loads(data)
        checked = tuple((a, b) for a, b in kept["checked"])
        skipped = {(a, b): reason for a, b, reason in kept["skipped"]}
    except (ValueError, KeyError, TypeError):
        return None
    if not {n for pair in [*checked, *skipped] for n in pair} <= set(names):
        return None
    return SelfCollisionMatrix(checked, skipped)


def _write(key: str, matrix: SelfCollisionMatrix) -> None:
    """Keep a matrix for the next build of the same robot."""
    kept = {
        "checked": matrix.checked,
        "skipped": [[a, b, r] for (a, b), r in matrix.skipped.items()],
    }
    keep(key, json.dumps(kept).encode())
