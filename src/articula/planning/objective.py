"""The objective of Eq. (1.13) and the projection onto the feasible set Ω, Eq. (1.17)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from articula.errors import ConfigError, ModelError
from articula.planning.baornn_kernel import Problem, Reference, outside_omega
from articula.planning.evaluation import (
    CompiledEvaluation,
    SceneEvaluation,
    evaluation_for,
)
from articula.planning.rate_limits import braking_after
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
        last: the motion of the period before, shape (nq,) [rad] (zeros: from rest).
        jerk: each joint's largest change of its change of motion per period, j·dt³, shape
            (nq,) [rad]; empty: no jerk limit (braking starts at once).
    """

    q_base: np.ndarray
    change: np.ndarray
    sweep: np.ndarray
    last: np.ndarray
    jerk: np.ndarray


NO_STOP = Stop(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))


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
    evaluation: CompiledEvaluation | SceneEvaluation = field(init=False, repr=False)

    def __post_init__(self) -> None:
        for name in ("lambda_weight", "beta", "d_min"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ConfigError(f"Objective.{name}", f"must be finite and >= 0 (got {value})")
        object.__setattr__(self, "evaluation", evaluation_for(self.scene, self.use_compiled))

    @property
    def compiled(self) -> CompiledClearance | None:
        """The compiled evaluation's arrays, where the scene allows it (revolute joints, no
        cylinders, GJK metric) and `use_compiled`; None: the Scene (Pinocchio + coal)."""
        return self.evaluation.compiled

    def problem(self, box: Box | None = None, t: float = 0.0, stop: Stop = NO_STOP) -> tuple:
        """g's weights and Ω as planning.baornn_kernel takes them (requires `compiled`).

        Args:
            box: projection box (lower, upper), each shape (nq,) [rad]; None: the joint limits.
            t: time, placing moving obstacles [s].
            stop: the period's braking check; NO_STOP: none.

        Returns:
            The Problem packed (compiled_bundles.packed), its clearance holding only the
            pairs that count (far ones pruned from a period's box).
        """
        robot, c = self.scene.robot, self.compiled
        if c is None:
            raise ModelError("this scene has no compiled evaluation (see Objective.compiled)")
        c.at(t)
        pairs, static_min = c.select(self.needs_obstacles, True)
        if box is not None:
            # A period's reach, and where braking from it ends: far obstacles drop out.
            pairs = c.near_pairs(pairs, _braking_box(box, stop), self.sweep)
        lower, upper = box or (robot.model.lowerPositionLimit, robot.model.upperPositionLimit)
        # Packed by hand: the clearance comes packed, and the rest are arrays and numbers.
        return tuple(Problem(self.lambda_weight, self.beta, self.d_min, self.self_d_min, lower,
                             upper, tuple(stop), c.inputs(pairs), static_min))  # fmt: skip

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

    def reference(self, target: Target) -> tuple:
        """A period's target as planning.baornn_kernel takes it.

        Args:
            target: the period's target.

        Returns:
            The Reference packed: its position, the task's code, weight and tool axis, and
            the reference rotation and axis.
        """
        R_ref, axis_ref = target_arrays(self.task, target)
        t = self.task
        return tuple(Reference(target.position, t.code, t.weight, t.tool_axis, R_ref, axis_ref))

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
        d, _, ee, ee_R = self.evaluation.measure(q, t, self.needs_obstacles, False)
        return self._combine(self._task_error(target, ee, ee_R), d)

    def tracking_error(self, q: np.ndarray, target: Target | np.ndarray) -> float:
        """The task term of g alone: ||x_r − f(θ)||, Eq. (1.5), plus the weighted
        orientation error of a pose or axis task.

        Args:
            q: joint angles, shape (nq,) [rad].
            target: the target, or a position, shape (3,) [m].

        Returns:
            The task error e [m].
        """
        _, _, ee, ee_R = self.evaluation.measure(q, None, False, False)
        return self._task_error(as_target(target), ee, ee_R)

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
        d, d_self, ee, ee_R = self.evaluation.measure(clipped, t, self.needs_obstacles, True)
        if outside_omega(d, d_self, self.d_min, self.self_d_min):
            return q_current, g_current
        omega = (self.d_min, self.self_d_min, self.needs_obstacles)
        if stop.change.size and not self.evaluation.brakes_clear(
            clipped, d, d_self, stop, t, omega
        ):
            return q_current, g_current
        return clipped, self._combine(self._task_error(target, ee, ee_R), d)

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


def _braking_box(box: Box, stop: Stop) -> Box:
    """`box` widened by the travel braking needs from its far corners (for the pruning of far
    obstacles: the braking check evaluates where the arm stops)."""
    if not stop.change.size:
        return box
    low, high = box[0] - stop.q_base, box[1] - stop.q_base
    widest = np.maximum(np.abs(low), np.abs(high))
    # The longest braking: the widest motion, still speeding up as fast as it can.
    extra = np.abs(braking_after(widest, widest - stop.change, stop.change, stop.jerk))
    return box[0] - extra, box[1] + extra
