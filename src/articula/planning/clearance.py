"""Link-obstacle and link-link distances near the robot with their gradients in joint space,
and the end effector's kinematics the resolved-rate controllers take with them."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from articula.planning.evaluation import CompiledEvaluation, SceneEvaluation, evaluation_for
from articula.scene import compiled_rows
from articula.scene.scene import Scene


@dataclass(frozen=True)
class ClearanceRows:
    """Distances d [m] of the (link, obstacle) cells and checked link pairs within reach,
    ∂d/∂q (rows, nq), and which rows are link pairs (self-collision).

    Attributes:
        distance: clearance of each row, negative on overlap, shape (rows,) [m].
        gradient: ∂d/∂q of each row, shape (rows, nq) [m/rad].
        self_pair: True where the row is a pair of links, shape (rows,).
    """

    distance: np.ndarray
    gradient: np.ndarray
    self_pair: np.ndarray


@dataclass(frozen=True)
class EndEffector:
    """The end effector at q: its position, rotation and Jacobian.

    Attributes:
        x: position in the world, shape (3,) [m].
        R: rotation in the world, shape (3, 3).
        J: Jacobian in world axes, linear rows first, shape (6, nq).
    """

    x: np.ndarray
    R: np.ndarray
    J: np.ndarray


class RowSource:
    """End-effector kinematics and clearance rows of a scene at q, in one compiled call where
    the scene allows it (CompiledClearance; for a period where a pair overlaps, or a scene it
    does not cover, through Pinocchio and coal: the same quantities, to GJK's tolerance).

    Args:
        scene: the robot, its obstacles and its checked link pairs.
        use_compiled: try the compiled evaluation (False: always Pinocchio and coal).
        evaluation: an evaluation of `scene` to share (an objective's); None: one of its own.

    Attributes:
        scene: the scene.
        evaluation: its clearance and end-effector measurement (planning/evaluation.py).
        compiled: the evaluation's compiled arrays, or None.
    """

    def __init__(
        self,
        scene: Scene,
        use_compiled: bool = True,
        evaluation: CompiledEvaluation | SceneEvaluation | None = None,
    ) -> None:
        self.scene = scene
        self.evaluation = evaluation or evaluation_for(scene, use_compiled)
        self.compiled = self.evaluation.compiled

    def __call__(
        self, q: np.ndarray, t: float, influence: float
    ) -> tuple[EndEffector, ClearanceRows]:
        """(the end effector, the rows closer than `influence` [m]) at q [rad], time t [s].

        Args:
            q: joint angles, shape (nq,) [rad].
            t: time, placing moving obstacles [s].
            influence: distance below which a row counts [m].

        Returns:
            The end effector's kinematics and the clearance rows that move with q.
        """
        if self.compiled is not None:
            self.compiled.at(t)
            out = compiled_rows.clearance_rows(self.compiled, q, influence)
            if out is not None:
                x, R, J, distance, gradient, self_pair = out
                return EndEffector(x, R, J), ClearanceRows(distance, gradient, self_pair)
        robot = self.scene.robot
        J = robot.jacobian(q)
        robot.forward(q)
        placement = robot.data.oMf[robot.ee_frame_id]
        end = EndEffector(placement.translation.copy(), placement.rotation.copy(), J)
        if not self.scene.has_clearance:
            return end, ClearanceRows(np.zeros(0), np.zeros((0, q.size)), np.zeros(0, bool))
        rows = clearance_rows(self.scene, q, t, influence)
        moving = np.any(rows.gradient != 0.0, axis=1)  # as the compiled rows: none fixed
        return end, ClearanceRows(
            rows.distance[moving], rows.gradient[moving], rows.self_pair[moving]
        )


def clearance_rows(scene: Scene, q: np.ndarray, t: float, influence: float) -> ClearanceRows:
    """Every cell and checked link pair closer than `influence` [m], with ḋ = ∇d · q̇ from
    its witness points.

    ∇d = n·J_p for a link and an obstacle, where n is the unit vector from the obstacle's
    closest point to the link's (flipped when the two overlap, so that ∇d still points toward
    more clearance) and J_p the Jacobian of the link's closest point; for links a and b,
    ∇d = n·(J_a − J_b) with n from b's closest point to a's.

    Args:
        scene: the robot, its obstacles and its checked link pairs.
        q: joint angles, shape (nq,) [rad].
        t: time, placing moving obstacles [s].
        influence: distance below which a cell or pair counts [m].

    Returns:
        The distances, their gradients in joint space and which rows are link pairs.
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
