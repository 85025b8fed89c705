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
    # Per row: its distance, the unit normal n, and the points whose motion moves it, each as
    # (frame, world point, +1 for link a | −1 for link b).
    rows: list[tuple[float, np.ndarray, list[tuple[int, np.ndarray, float]]]] = []
    w = scene.witnesses(q, t)
    for li, oi in zip(*np.nonzero(w.distance < influence), strict=True):
        n = _normal(w.distance[li, oi], w.on_link[li, oi], w.on_obstacle[li, oi])
        if n is not None:
            on_link = [(robot.links[li].frame_id, w.on_link[li, oi], 1.0)]
            rows.append((w.distance[li, oi], n, on_link))
    n_obstacle_rows = len(rows)
    if scene.self_pairs:
        s = scene.self_witnesses(q)
        for k in np.nonzero(s.distance < influence)[0]:
            n = _normal(s.distance[k], s.on_a[k], s.on_b[k])
            if n is not None:
                a, b = scene.self_pairs[k]
                ends = [(robot.links[a].frame_id, s.on_a[k], 1.0),
                        (robot.links[b].frame_id, s.on_b[k], -1.0)]  # fmt: skip
                rows.append((s.distance[k], n, ends))
    terms = [term for _, _, row_terms in rows for term in row_terms]
    jacobians = iter(robot.point_jacobians(q, [f for f, _, _ in terms], [p for _, p, _ in terms]))
    grads = [n @ sum(sign * next(jacobians) for _, _, sign in row_terms)
             for _, n, row_terms in rows]  # fmt: skip
    flags = np.arange(len(rows)) >= n_obstacle_rows
    distances = np.array([d for d, _, _ in rows])
    return ClearanceRows(distances, np.array(grads).reshape(len(rows), robot.nq), flags)


def _normal(d: float, on_a: np.ndarray, on_b: np.ndarray) -> np.ndarray | None:
    """The unit normal from b's closest point to a's, toward more clearance (flipped when
    they overlap); None when the points coincide and there is no direction to move along."""
    gap = on_a - on_b
    length = np.linalg.norm(gap)
    if length < 1e-9:
        return None
    return gap / length * (1.0 if d >= 0 else -1.0)
