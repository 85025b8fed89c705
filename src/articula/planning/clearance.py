"""Link-obstacle and link-link distances near the robot with their gradients in joint space."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from articula.scene.scene import Scene


@dataclass(frozen=True)
class ClearanceRows:
    """Distances d [m] of the (link, obstacle) cells and checked link pairs within reach,
    ∂d/∂q (rows, nq), and which rows are link pairs (self-collision)."""

    distance: np.ndarray
    gradient: np.ndarray
    self_pair: np.ndarray


def clearance_rows(scene: Scene, q: np.ndarray, t: float, influence: float) -> ClearanceRows:
    """Every cell and checked link pair closer than `influence` [m], with ḋ = ∇d · q̇ from
    its witness points.

    ∇d = n·J_p for a link and an obstacle, where n is the unit vector from the obstacle's
    closest point to the link's (flipped when the two overlap, so that ∇d still points toward
    more clearance) and J_p the Jacobian of the link's closest point; for links a and b,
    ∇d = n·(J_a − J_b) with n from b's closest point to a's.
    """
    robot = scene.robot
    distances, normals, flags = [], [], []
    frames, points, row_of = [], [], []  # each point that moves a row, with its sign below
    signs = []
    w, s = scene.witnesses_within(q, t, influence)
    for li, oi in zip(*np.nonzero(w.distance < influence), strict=True):
        n = _normal(w.distance[li, oi], w.on_link[li, oi], w.on_obstacle[li, oi])
        if n is not None:
            row_of.append(len(distances))
            frames.append(robot.links[li].frame_id)
            points.append(w.on_link[li, oi])
            signs.append(1.0)
            distances.append(w.distance[li, oi])
            normals.append(n)
            flags.append(False)
    for k in np.nonzero(s.distance < influence)[0]:
        n = _normal(s.distance[k], s.on_a[k], s.on_b[k])
        if n is not None:
            a, b = scene.self_pairs[k]
            row_of += [len(distances), len(distances)]
            frames += [robot.links[a].frame_id, robot.links[b].frame_id]
            points += [s.on_a[k], s.on_b[k]]
            signs += [1.0, -1.0]  # link b moving along n brings the two closer
            distances.append(s.distance[k])
            normals.append(n)
            flags.append(True)
    gradient = np.zeros((len(distances), robot.nq))
    if frames:
        directions = np.array(normals)[row_of] * np.array(signs)[:, None]
        terms = robot.directional_gradients(q, frames, np.array(points), directions)
        np.add.at(gradient, row_of, terms)
    return ClearanceRows(np.array(distances), gradient, np.array(flags, dtype=bool))


def _normal(d: float, on_a: np.ndarray, on_b: np.ndarray) -> np.ndarray | None:
    """The unit normal from b's closest point to a's, toward more clearance (flipped when
    they overlap); None when the points coincide and there is no direction to move along."""
    gap = on_a - on_b
    length = math.sqrt(gap @ gap)
    if length < 1e-9:
        return None
    return gap * ((1.0 if d >= 0 else -1.0) / length)
