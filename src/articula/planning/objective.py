"""The objective of Eq. (1.13) and the projection onto the feasible set Ω, Eq. (1.17)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from articula.errors import ConfigError, ModelError
from articula.planning.baornn_kernel import outside_omega, stoppable
from articula.planning.task import Target, Task, as_target, target_arrays
from articula.robots.sweep import joint_sweep
from articula.scene.compiled_clearance import CompiledClearance
from articula.scene.scene import Scene

Box = tuple[np.ndarray, np.ndarray]  # (lower, upper) of the configurations allowed [rad]


class Stop(NamedTuple):
    """A period's braking check (baornn_kernel.stoppable): from where the period started and
    how fast each joint can brake.

    Attributes:
        q_base: the configuration at the period's start, shape (nq,) [rad].
        change: each joint's largest change of motion per period, a·dt², shape (nq,) [rad];
            empty: no acceleration limit, no check.
        sweep: how far a point of the arm moves at most per unit of each joint's motion,
            shape (nq,) [m/rad] (robots.sweep.joint_sweep).
    """

    q_base: np.ndarray
    change: np.ndarray
    sweep: np.ndarray


NO_STOP = Stop(np.zeros(0), np.zeros(0), np.zeros(0))


@dataclass(frozen=True)
class Objective:
    """g = ||x_r − f(θ)|| + Λ / (min_i d_i)^β, Eqs. (1.5), (1.7), (1.11), (1.14).

    lambda_weight is Λ, beta is β, d_min [m] the hard clearance of Eq. (1.12). With several
    obstacles, Eq. (1.14) takes the largest penalty, i.e. the smallest distance over all of
    them. Beyond the book, a pose or axis `task` adds w · (orientation error) [m] to the
    tracking term (docs/deviations.md).

    Attributes:
        scene: the robot, its obstacles and its checked link pairs.
        lambda_weight: penalty weight Λ [m^(1+β)] (0: no penalty).
        beta: penalty exponent β.
        d_min: hard clearance of Eq. (1.12) [m].
        use_compiled: evaluate by CompiledClearance where the scene allows it.
        task: what the end effector tracks, and the weight w of its orientation error.
    """

    scene: Scene
    lambda_weight: float
    beta: float = 1.0
    d_min: float = 0.0
    use_compiled: bool = True
    task: Task = field(default_factory=Task)
    # The compiled evaluation of the same objective, when allowed and the scene permits it
    # (static obstacles, revolute joints, no cylinders, GJK metric); None: Scene (Pinocchio +
    # coal) is used.
    compiled: CompiledClearance | None = field(init=False, default=None, repr=False)

    def __post_init__(self) -> None:
        for name in ("lambda_weight", "beta", "d_min"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ConfigError(f"Objective.{name}", f"must be finite and >= 0 (got {value})")
        if self.use_compiled:
            object.__setattr__(self, "compiled", CompiledClearance.build(self.scene))

    def kernel_arguments(
        self, box: Box | None = None, t: float = 0.0, stop: Stop = NO_STOP
    ) -> tuple:
        """The objective's arguments to planning.baornn_kernel (requires `compiled`).

        Args:
            box: projection box (lower, upper), each shape (nq,) [rad]; None: the joint limits.
            t: time, placing moving obstacles [s].
            stop: the period's braking check; NO_STOP: none.

        Returns:
            (Λ, β, d_min, self_d_min, lower, upper, stop, the compiled scene arrays with the
            pairs that count, their static minima), in the order of planning.baornn_kernel.
        """
        robot, c = self.scene.robot, self.compiled
        if c is None:
            raise ModelError("this scene has no compiled evaluation (see Objective.compiled)")
        c.at(t)
        pairs, static_min = c.select(self.needs_obstacles, True)
        if box is not None:
            # A period's reach, and where braking from it ends: far obstacles drop out.
            pairs = c.near_pairs(pairs, _braking_box(box, stop))
        lower, upper = box or (robot.model.lowerPositionLimit, robot.model.upperPositionLimit)
        return (
            self.lambda_weight,
            self.beta,
            self.d_min,
            self.self_d_min,
            lower,
            upper,
            tuple(stop),
            c.arrays(pairs),
            static_min,
        )

    @cached_property
    def sweep(self) -> np.ndarray:
        """How far a point of the arm moves at most per unit of each joint's motion, shape
        (nq,) [m/rad] (robots.sweep.joint_sweep)."""
        return joint_sweep(self.scene.robot)

    @property
    def self_d_min(self) -> float:
        """The hard clearance [m] between the links of a checked pair (the scene's)."""
        return self.scene.self_d_min

    @property
    def needs_obstacles(self) -> bool:
        """False when neither the penalty nor the hard bound uses the obstacles (Λ = d_min = 0):
        then no link-obstacle distance is computed at all."""
        return bool(self.scene.obstacles) and (self.lambda_weight > 0 or self.d_min > 0)

    def orient_arguments(self, target: Target) -> tuple:
        """The task and the target's orientation as planning.baornn_kernel takes them.

        Args:
            target: the period's target.

        Returns:
            (task code, weight, tool axis, reference rotation, reference axis).
        """
        R_ref, axis_ref = target_arrays(self.task, target)
        return (self.task.code, self.task.weight, self.task.tool_axis, R_ref, axis_ref)

    def kinematics_arguments(self) -> tuple:
        """The compiled scene arrays without any pair: forward kinematics only.

        Returns:
            The arguments of the compiled evaluation after q, with no pair to check.
        """
        if self.compiled is None:
            raise ModelError("this scene has no compiled evaluation (see Objective.compiled)")
        return self.compiled.arrays(self.compiled.no_pairs)

    def value(self, q: np.ndarray, target: Target | np.ndarray, t: float = 0.0) -> float:
        """Objective g at configuration q [rad] for the target (or a position [m]).

        Args:
            q: joint angles, shape (nq,) [rad].
            target: the target, or a position, shape (3,) [m].
            t: time, placing moving obstacles [s].

        Returns:
            The objective g; inf inside an obstacle when Λ > 0.
        """
        target = as_target(target)
        if self.compiled is not None:
            self.compiled.at(t)
            d, _, ee, ee_R = self.compiled.evaluate(q, self.needs_obstacles, False)
            return self._combine(self._task_error(target, ee, ee_R), d)
        d = self.scene.clearances(q, t)[0] if self.needs_obstacles else np.inf
        return self._value(q, target, d)

    def tracking_error(self, q: np.ndarray, target: Target | np.ndarray) -> float:
        """The task term of g alone: ||x_r − f(θ)||, Eq. (1.5), plus the weighted
        orientation error of a pose or axis task.

        Args:
            q: joint angles, shape (nq,) [rad].
            target: the target, or a position, shape (3,) [m].

        Returns:
            The task error e [m].
        """
        target = as_target(target)
        if self.compiled is not None:
            _, _, ee, ee_R = self.compiled.evaluate(q, False, False)
            return self._task_error(target, ee, ee_R)
        robot = self.scene.robot
        robot.forward(q)
        placement = robot.data.oMf[robot.ee_frame_id]
        return self._task_error(target, placement.translation, placement.rotation)

    def project_and_value(
        self,
        q: np.ndarray,
        q_current: np.ndarray,
        g_current: float,
        target: Target | np.ndarray,
        t: float,
        box: Box | None = None,
        stop: Stop = NO_STOP,
    ) -> tuple[np.ndarray, float]:
        """(P_Ω(q), g there), Eqs. (1.17)-(1.18): clip to the joint limits (1.9), or to `box`
        (the joint limits narrowed by speed limits); if the clipped point is closer than d_min
        to an obstacle or than self_d_min between the links of a checked pair, or with `stop`
        cannot brake without coming that close, stay at (q_current, g_current).
        One distance query serves both the constraints and the penalty.

        Args:
            q: candidate joint angles, shape (nq,) [rad].
            q_current: joint angles kept if the candidate is infeasible, shape (nq,) [rad].
            g_current: the objective at q_current.
            target: the target, or a position, shape (3,) [m].
            t: time, placing moving obstacles [s].
            box: projection box (lower, upper), each shape (nq,) [rad]; None: the joint limits.
            stop: the period's braking check; NO_STOP: none.

        Returns:
            The projected joint angles, shape (nq,) [rad], and g there; or q_current and
            g_current.
        """
        target = as_target(target)
        clipped = self.scene.robot.clip(q) if box is None else np.clip(q, *box)
        if self.compiled is not None:
            self.compiled.at(t)
            d, d_self, ee, ee_R = self.compiled.evaluate(clipped, self.needs_obstacles)
            if outside_omega(d, d_self, self.d_min, self.self_d_min) or not self._stoppable(
                clipped, d, d_self, stop, t
            ):
                return q_current, g_current
            return clipped, self._combine(self._task_error(target, ee, ee_R), d)
        if not (self.needs_obstacles or self.scene.self_pairs):
            return clipped, self._value(clipped, target, np.inf)
        d, d_self = self.scene.clearances(clipped, t)
        if not self.needs_obstacles:
            d = np.inf
        if outside_omega(d, d_self, self.d_min, self.self_d_min):
            return q_current, g_current
        if stop.change.size:
            d_end = self._stoppable(clipped, d, d_self, stop, t)
            self.scene.robot.forward(clipped)  # the braking check moved the placements
            if not d_end:
                return q_current, g_current
        return clipped, self._value(clipped, target, d, kinematics_done=True)

    def _stoppable(self, q: np.ndarray, d: float, d_self: float, stop: Stop, t: float) -> bool:
        """baornn_kernel.stoppable at q with clearances (d, d_self) [m], compiled or through
        the Scene (which evaluates the point where braking ends in any case)."""
        if not stop.change.size:
            return True
        c = self.compiled
        if c is not None:
            pairs, static_min = c.select(self.needs_obstacles, True)
            return stoppable(
                q, d, d_self, self.d_min, self.self_d_min, tuple(stop), c.arrays(pairs), static_min
            )
        q_stop = q + braking_travel(q - stop.q_base, stop.change)
        d_stop, d_self_stop = self.scene.clearances(q_stop, t)
        if not self.needs_obstacles:
            d_stop = np.inf
        return not outside_omega(d_stop, d_self_stop, self.d_min, self.self_d_min)

    def _value(
        self, q: np.ndarray, target: Target, d: float, kinematics_done: bool = False
    ) -> float:
        robot = self.scene.robot
        if kinematics_done:
            # min_distance ran the forward kinematics: only the end-effector frame is missing.
            pin.updateFramePlacement(robot.model, robot.data, robot.ee_frame_id)
        else:
            robot.forward(q)
        placement = robot.data.oMf[robot.ee_frame_id]
        return self._combine(self._task_error(target, placement.translation, placement.rotation), d)

    def _task_error(self, target: Target, ee: np.ndarray, ee_R: np.ndarray) -> float:
        """||x_r − f(θ)|| [m] (Eq. 1.5), plus w · orientation error for a pose or axis task."""
        e = target.position - ee
        error = math.sqrt(e @ e)  # np.linalg.norm costs more than the rest for 3 numbers
        if self.task.kind != "position":
            error += self.task.weight * self.task.orientation_error(ee_R, target)
        return error

    def _combine(self, error: float, d: float) -> float:
        """g from the task error [m] and the clearance d [m]."""
        g = error
        if self.lambda_weight > 0 and d < np.inf:
            # Eq. (1.7): inside an obstacle the penalty has no finite value.
            g += self.lambda_weight / d**self.beta if d > 0 else np.inf
        return g


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


def _braking_box(box: Box, stop: Stop) -> Box:
    """`box` widened by the travel braking needs from its far corners (for the pruning of far
    obstacles: the braking check evaluates where the arm stops)."""
    if not stop.change.size:
        return box
    low, high = box[0] - stop.q_base, box[1] - stop.q_base
    widest = np.maximum(np.abs(low), np.abs(high))
    extra = np.abs(braking_travel(widest, stop.change))
    return box[0] - extra, box[1] + extra
