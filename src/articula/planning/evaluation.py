"""How the objective measures a configuration: by the compiled evaluation where the scene
allows it, else through the Scene (Pinocchio + coal). `evaluation_for` makes that choice, once
per objective; everything above asks the chosen evaluation and never checks again.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from articula.planning.baornn_kernel import outside_omega, stoppable
from articula.scene.compiled_clearance import CompiledClearance
from articula.scene.scene import Scene

# (obstacle clearance [m], self clearance [m], end-effector position [m], rotation (3×3))
Measured = tuple[float, float, np.ndarray, np.ndarray]


def braking_travel(motion: np.ndarray, change: np.ndarray) -> np.ndarray:
    """How far [rad] each joint moves on, after a period's `motion`, when it brakes at its
    largest change of motion per period `change` (m·|m|/(2c), 0 where c is inf).

    Args:
        motion: the joint motion over the period, shape (nq,) [rad].
        change: the largest change of motion per period, a·dt², shape (nq,) [rad].

    Returns:
        The signed travel until each joint stops, shape (nq,) [rad].
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        travel = motion * np.abs(motion) / (2.0 * change)
    return np.where(np.isfinite(change), travel, 0.0)


class CompiledEvaluation:
    """The compiled evaluation (scene/compiled_clearance.py) of a scene.

    Args:
        compiled: the scene's arrays.

    Attributes:
        compiled: the scene's arrays (their scratch changes at every measurement).
    """

    def __init__(self, compiled: CompiledClearance) -> None:
        self.compiled = compiled

    def measure(
        self, q: np.ndarray, t: float | None, obstacles: bool, self_pairs: bool
    ) -> Measured:
        """The clearances asked for (+inf for the others) and the end-effector pose at q.

        Args:
            q: joint angles, shape (nq,) [rad].
            t: time, placing moving obstacles [s]; None: they stay where they are.
            obstacles: whether to measure the link-obstacle clearance.
            self_pairs: whether to measure the checked link pairs' clearance.

        Returns:
            (obstacle clearance [m], self clearance [m], end-effector position, shape (3,)
            [m], end-effector rotation, shape (3, 3)).
        """
        if t is not None:
            self.compiled.at(t)
        return self.compiled.evaluate(q, obstacles, self_pairs)

    def brakes_clear(
        self, q: np.ndarray, d: float, d_self: float, stop: tuple, t: float, omega: tuple
    ) -> bool:
        """baornn_kernel.stoppable at q.

        Args:
            q: joint angles at the end of the period, shape (nq,) [rad].
            d: the obstacle clearance there [m].
            d_self: the self clearance there [m].
            stop: the period's braking check (objective.Stop).
            t: time, placing moving obstacles [s].
            omega: (d_min [m], self_d_min [m], whether the obstacles count).

        Returns:
            Whether braking from q ends inside Ω.
        """
        d_min, self_d_min, obstacles = omega
        pairs, static_min = self.compiled.select(obstacles, True)
        inputs = self.compiled.inputs(pairs)
        return stoppable(q, d, d_self, d_min, self_d_min, tuple(stop), inputs, static_min)


class SceneEvaluation:
    """The Scene's evaluation: Pinocchio kinematics and coal distances.

    Args:
        scene: the robot, its obstacles and its checked link pairs.

    Attributes:
        scene: the scene.
        compiled: None (no compiled evaluation).
    """

    compiled = None

    def __init__(self, scene: Scene) -> None:
        self.scene = scene

    def measure(
        self, q: np.ndarray, t: float | None, obstacles: bool, self_pairs: bool
    ) -> Measured:
        """The clearances asked for (+inf for the others) and the end-effector pose at q.

        Args:
            q: joint angles, shape (nq,) [rad].
            t: time, placing moving obstacles [s]; None: they stay where they are.
            obstacles: whether to measure the link-obstacle clearance.
            self_pairs: whether to measure the checked link pairs' clearance.

        Returns:
            (obstacle clearance [m], self clearance [m], end-effector position, shape (3,)
            [m], end-effector rotation, shape (3, 3)).
        """
        robot = self.scene.robot
        d = d_self = np.inf
        if obstacles or (self_pairs and self.scene.self_pairs):
            # The distances run the forward kinematics: only the end-effector frame is missing.
            d, d_self = self.scene.clearances(q, 0.0 if t is None else t)
            pin.updateFramePlacement(robot.model, robot.data, robot.ee_frame_id)
        else:
            robot.forward(q)
        placement = robot.data.oMf[robot.ee_frame_id]
        d = d if obstacles else np.inf
        d_self = d_self if self_pairs else np.inf
        return d, d_self, placement.translation.copy(), placement.rotation.copy()

    def brakes_clear(
        self, q: np.ndarray, d: float, d_self: float, stop: tuple, t: float, omega: tuple
    ) -> bool:
        """Whether the point where braking from q ends is inside Ω (measured there).

        Args:
            q: joint angles at the end of the period, shape (nq,) [rad].
            d: the obstacle clearance there [m] (not needed: the end point is measured).
            d_self: the self clearance there [m] (likewise).
            stop: the period's braking check (objective.Stop).
            t: time, placing moving obstacles [s].
            omega: (d_min [m], self_d_min [m], whether the obstacles count).

        Returns:
            Whether braking from q ends inside Ω.
        """
        d_min, self_d_min, obstacles = omega
        q_base, change, _ = stop
        q_stop = q + braking_travel(q - q_base, change)
        d_stop, d_self_stop = self.scene.clearances(q_stop, t)
        return not outside_omega(d_stop if obstacles else np.inf, d_self_stop, d_min, self_d_min)


def evaluation_for(scene: Scene, use_compiled: bool) -> CompiledEvaluation | SceneEvaluation:
    """The compiled evaluation of `scene` where allowed and possible, else the Scene's.

    Args:
        scene: the scene to evaluate.
        use_compiled: whether the compiled evaluation may be used.

    Returns:
        The evaluation.
    """
    compiled = CompiledClearance.build(scene) if use_compiled else None
    return SceneEvaluation(scene) if compiled is None else CompiledEvaluation(compiled)
