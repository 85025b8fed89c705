"""Link-obstacle and link-link distances near the robot with their gradients in joint space."""

from __future__ import annotations

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
    rows, normals = [], []
    frames, points = [], []  # the point on the link (a) that ∇d follows
    pairs = []  # per row: None, or the frame and point of link b
    w = scene.witnesses(q, t)
    for li, oi in zip(*np.nonzero(w.distance < influence), strict=True):
        if _add_row(rows, normals, w.distance[li, oi], w.on_link[li, oi], w.on_obstacle[li, oi]):
            frames.append(robot.links[li].frame_id)
            points.append(w.on_link[li, oi])
            pairs.append(None)
    if scene.self_pairs:
        s = scene.self_witnesses(q)
        for k in np.nonzero(s.distance < influence)[0]:
            if _add_row(rows, normals, s.distance[k], s.on_a[k], s.on_b[k]):
                a, b = scene.self_pairs[k]
                frames.append(robot.links[a].frame_id)
                points.append(s.on_a[k])
                pairs.append((robot.links[b].frame_id, s.on_b[k]))
    others = [pair for pair in pairs if pair is not None]
    jacobians = robot.point_jacobians(
        q, frames + [f for f, _ in others], points + [p for _, p in others]
    )
    grads, e = [], len(frames)
    for n, J, pair in zip(normals, jacobians, pairs, strict=False):
        if pair is None:
            grads.append(n @ J)
        else:
            grads.append(n @ (J - jacobians[e]))
            e += 1
    flags = np.array([pair is not None for pair in pairs], dtype=bool)
    return ClearanceRows(np.array(rows), np.array(grads).reshape(len(rows), robot.nq), flags)


def _add_row(rows: list, normals: list, d: float, on_a: np.ndarray, on_b: np.ndarray) -> bool:
    """Append d and the unit normal from b to a (toward more clearance); False when the
    points coincide and there is no direction to move away along."""
    gap = on_a - on_b
    length = np.linalg.norm(gap)
    if length < 1e-9:
        return False
    rows.append(d)
    normals.append(gap / length * (1.0 if d >= 0 else -1.0))
    return True
