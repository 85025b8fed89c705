"""Link-obstacle distances near the robot with their gradients in joint space."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from articula.scene.scene import Scene


@dataclass(frozen=True)
class ClearanceRows:
    """Distances d [m] of the (link, obstacle) cells within reach, and ∂d/∂q (rows, nq)."""

    distance: np.ndarray
    gradient: np.ndarray


def clearance_rows(scene: Scene, q: np.ndarray, t: float, influence: float) -> ClearanceRows:
    """Every cell closer than `influence` [m], with ḋ = ∇d · q̇ from its witness points.

    ∇d = n·J_p, where n is the unit vector from the obstacle's closest point to the link's
    (flipped when the two overlap, so that ∇d still points toward more clearance) and J_p the
    Jacobian of the link's closest point.
    """
    robot = scene.robot
    w = scene.witnesses(q, t)
    rows, normals, frames, points = [], [], [], []
    for li, oi in zip(*np.nonzero(w.distance < influence), strict=True):
        d = w.distance[li, oi]
        gap = w.on_link[li, oi] - w.on_obstacle[li, oi]
        length = np.linalg.norm(gap)
        if length < 1e-9:
            continue  # touching: no direction to move away along
        rows.append(d)
        normals.append(gap / length * (1.0 if d >= 0 else -1.0))
        frames.append(robot.links[li].frame_id)
        points.append(w.on_link[li, oi])
    jacobians = robot.point_jacobians(q, frames, points)
    grads = [n @ J for n, J in zip(normals, jacobians, strict=True)]
    return ClearanceRows(np.array(rows), np.array(grads).reshape(len(rows), robot.nq))
