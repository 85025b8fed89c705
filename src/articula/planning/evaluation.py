"""How the objective measures a configuration: by the compiled evaluation where the scene
allows it, else through the Scene (Pinocchio + coal). `evaluation_for` makes that choice, once
per objective; everything above asks the chosen evaluation and never checks again.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from articula.planning.baornn_kernel import outside_omega, stoppable
from articula.planning.rate_limits import braking_path
from articula.scene.compiled_clearance import CompiledClearance
from articula.scene.scene import Scene

# (obstacle clearance [m], self clearance [m], end-effector position [m], rotation (3×3))
Measured = tuple[float, float, np.ndarray, np.ndarray]


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
        """Whether braking from q stays inside Ω (baornn_kernel.stoppable's points: the end of
        every braking period, each measured).

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
        q_base, change, _, last, jerk = stop
        for offset in braking_path(q - q_base, last, change, jerk):
            d_k, d_self_k = self.scene.clearances(q + offset, t)
            if outside_omega(d_k if obstacles else np.inf, d_self_k, d_min, self_d_min):
                return False
        return True


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
