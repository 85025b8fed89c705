"""BAORNN (Algorithm 1): beetle-antennae search over joint angles, one time-step at a time.

Beyond the book, with acceleration limits both searches (this and baornn-improved) end each
period where g descends from the search's point with the least acceleration
(planning/smooth.py, `smoothing = "acceleration"`): the search's random steps land on the faces
of the period's box, and an arm would be commanded its acceleration limits at ~20 Hz.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Annotated, Literal

import numpy as np
import pinocchio as pin
from pydantic import Field

from articula.planning import baornn_kernel as kernel
from articula.planning.clearance import ClearanceRows, EndEffector, RowSource
from articula.planning.newton_step import task_residual
from articula.planning.objective import NO_STOP, Box, Objective, Stop
from articula.planning.planner import WARM_UP_STEPS
from articula.planning.rate_limits import RateLimits
from articula.planning.slide import SLIDE_MARGIN
from articula.planning.smooth import (
    PENALTY_REACH,
    SMOOTH_BAND,
    keep_off_gradient,
    penalty_gradient,
    smooth_change,
    torque_rows,
    torques_known,
)
from articula.planning.task import Target, Task, as_target
from articula.robots.model import RobotModel
from articula.scene.scene import Scene
from articula.validation import Positive, StrictModel


class BaornnParams(StrictModel):
    """Step constants of Algorithm 1.

    Attributes:
        c1: antenna length λ_k = c1·√g_k, Eq. (1.23) [rad/√m].
        c2: step δ_k = c2·λ_k, Eq. (1.24) [-].
        iterations_per_step: iterations per control period.
        smoothing: "acceleration": each period ends at the smallest change of motion that
            meets the task from the search's point (planning/smooth.py, beyond the book);
            "none": where the search left it, as Algorithm 1 (the book's commands).
    """

    c1: Positive = 0.5
    c2: Positive = 0.5
    iterations_per_step: Annotated[int, Field(ge=1, le=10_000)] = 10
    smoothing: Literal["acceleration", "none"] = "acceleration"


@dataclass
class BeetleSearch:
    """What both BAORNN variants hold: the objective they search, their step constants, the
    generator of all their randomness, and counts of objective evaluations and iterations.

    Attributes:
        objective: the objective g of Eq. (1.13) searched, with its scene and task.
        params: the step constants of Algorithm 1.
        rng: the generator of all the search's randomness (seed it for a reproducible run).
        rate: joint speed and acceleration limits; None: unlimited, as in the book.
        evaluations: objective evaluations so far.
        iterations: iterations of Algorithm 1 so far.
        infeasible: periods that ended outside Ω (closer than d_min or self_d_min: the limits
            left no way out) or whose limits could not all hold (RateLimits.strained).
    """

    objective: Objective
    params: BaornnParams
    rng: np.random.Generator
    rate: RateLimits | None = None
    evaluations: int = field(default=0, init=False)
    iterations: int = field(default=0, init=False)
    infeasible: int = field(default=0, init=False)
    _box: Box | None = field(default=None, init=False, repr=False)  # this period's reach
    _stop: Stop = field(default=NO_STOP, init=False, repr=False)  # its braking check
    _rows: RowSource = field(init=False, repr=False)  # clearance rows and task Jacobian
    _dynamics: pin.Data | None = field(init=False, repr=False)  # torque rows' scratch, if any
    # The last command and its motion: the smoothing shapes the commands, which a measured
    # arm (follow) lags.
    _sent: tuple[np.ndarray, np.ndarray] | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self._rows = RowSource(self.objective.scene, evaluation=self.objective.evaluation)
        model = self.objective.scene.robot.model
        self._dynamics = model.createData() if torques_known(model) else None  # once, not a period

    def reset(self) -> None:
        """Forget the previous periods: the arm starts at rest."""
        if self.rate is not None:
            self.rate.reset()
        self._sent = None

    def warm_up(self, q: np.ndarray, target: Target) -> None:
        """Compile (or load) the kernels of a step by taking WARM_UP_STEPS of them (the
        interpreter specialises what runs a few times); the counts and the random state are put
        back (reset() forgets the steps' motion).

        Args:
            q: a configuration to step from, shape (nq,) [rad].
            target: a target to step toward.
        """
        state = self.rng.bit_generator.state
        counts = (self.evaluations, self.iterations, self.infeasible)
        for _ in range(WARM_UP_STEPS):
            self.step(q.copy(), target, 0.0)
        self.rng.bit_generator.state = state
        self.evaluations, self.iterations, self.infeasible = counts

    def follow(self, motion: np.ndarray) -> None:
        """Take the arm's measured joint motion [rad] over the period that ended as its motion:
        the next period's limits hold relative to it.

        Args:
            motion: the measured joint displacement over the last period, shape (nq,) [rad].
        """
        if self.rate is not None:
            self.rate.record(motion)

    def _begin_period(
        self, q: np.ndarray, target: Target, t: float
    ) -> tuple[np.ndarray, float] | None:
        """Narrow this period's search to what the joint limits let it reach, and start it at
        the better of braking (the point of that box nearest q) and coasting (q plus the last
        motion), g = inf outside Ω; None without limits (the book's start at q)."""
        if not self._limit_period(q):
            return None
        obj = self.objective
        brake = np.clip(q, *self._box)
        start = obj.project_and_value(brake, brake, math.inf, target, t, (brake, brake), self._stop)
        self.evaluations += 1
        last = self.rate.last_motion
        if last is not None:
            coast = obj.project_and_value(
                q + last, brake, math.inf, target, t, self._box, self._stop
            )
            self.evaluations += 1
            if coast[1] < start[1]:
                start = coast
        return start

    def _limit_period(self, q: np.ndarray) -> bool:
        """Set this period's box and braking check from q [rad]; False without limits."""
        if self.rate is None:
            self._box, self._stop = None, NO_STOP
            return False
        robot = self.objective.scene.robot
        rate = self.rate
        last = np.zeros_like(q) if rate.last_motion is None else rate.last_motion
        self._box = rate.box(q, robot.lower, robot.upper)
        jerk = np.zeros(0) if rate.jerk_change is None else rate.jerk_change
        change = rate.change
        self._stop = (
            NO_STOP if change is None else Stop(q, change, self.objective.sweep, last, jerk)
        )
        return True

    def _smooth(
        self, start: np.ndarray, q: np.ndarray, g: float, target: Target, t: float
    ) -> tuple[np.ndarray, float]:
        """The period's end re-chosen to use as little of the acceleration limits as the task
        allows from the search's (q, g) (planning/smooth.py), projected onto Ω (1.17) with the
        braking check; returns the period's (q, g). Without acceleration limits, with smoothing
        "none", or where the search's point or the smoothed one is outside Ω, the search's."""
        rate, obj = self.rate, self.objective
        if self.params.smoothing == "none" or rate is None or not math.isfinite(g):
            return q, g
        scale = rate.change
        if scale is None or not np.all(np.isfinite(scale) & (scale > 0)):
            return q, g
        # Coasting from the commands: the same as from the start and the last motion, unless
        # the start is a measured arm's, which lags them.
        if self._sent is None:
            motion = np.zeros_like(start) if rate.last_motion is None else rate.last_motion
            coast = start + motion
        else:  # in the start's branch: a continuous joint's command may have been wrapped
            motion = self._sent[1]
            coast = self._sent[0] + _turns(obj.scene.robot, start - self._sent[0]) + motion
        floors = (obj.d_min, obj.self_d_min)
        reach = max(max(floors) + SLIDE_MARGIN + SMOOTH_BAND, PENALTY_REACH)
        end, rows = self._rows(q, t, reach)
        A, residual = self._task_rows(end, target)
        low, high = (bound - coast for bound in self._box)
        robot = obj.scene.robot
        push = penalty_gradient(rows, obj.lambda_weight, obj.beta)
        keep_off = keep_off_gradient(
            q, (robot.lower, robot.upper), rows, obj.self_d_min, obj.lambda_weight, obj.beta
        )
        change = smooth_change(
            q - coast, motion, scale, A, residual, rows, floors, low, high, push,
            self._error_cap(rows), keep_off,
            self._torque_rows(coast - motion, motion / rate.dt, rate.dt),
        )  # fmt: skip
        self.evaluations += 1
        if change is None:
            return q, g
        # Refused (outside Ω, or braking from it would leave Ω): the search's point.
        return obj.project_and_value(coast + change, q, g, target, t, self._box, self._stop)

    def _torque_rows(
        self, q: np.ndarray, velocity: np.ndarray, dt: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The torque rows at the period's end; None where the URDF gives no dynamics."""
        if self._dynamics is None:
            return None
        return torque_rows(self.objective.scene.robot.model, self._dynamics, q, velocity, dt)

    def _error_cap(self, rows: ClearanceRows) -> float:
        """How far off the path the smoothing lets g's penalty trade the task for clearance
        [m] (smooth_change's error_cap): as far as g does."""
        return math.inf

    def _task_rows(self, end: EndEffector, target: Target) -> tuple[np.ndarray, np.ndarray]:
        """(A, r): the task's Jacobian rows [m/rad] and residual [m] at the end effector."""
        r = kernel.Reference(*self.objective.reference(target))
        return task_residual(
            end.x, np.ascontiguousarray(end.R), end.J,
            r.task, r.weight, r.position, r.tool_axis, r.rotation, r.axis,
        )  # fmt: skip

    def _end_period(self, start: np.ndarray, q: np.ndarray, g: float) -> np.ndarray:
        """Remember the period's motion for the acceleration limit, count it when it ended
        outside Ω (g = inf) or its limits were strained; returns q."""
        if self.rate is not None:
            self.rate.record(q - start)
            if self.rate.strained or not math.isfinite(g):
                self.infeasible += 1
        before = start if self._sent is None else self._sent[0]
        motion = q - before
        self._sent = (q, motion - _turns(self.objective.scene.robot, motion))
        return q

    @property
    def scene(self) -> Scene:
        """The scene of the objective."""
        return self.objective.scene

    @property
    def d_min(self) -> float:
        """The hard clearance [m] of the objective (Eq. 1.12)."""
        return self.objective.d_min

    @property
    def task(self) -> Task:
        """The task of the objective."""
        return self.objective.task


class Baornn(BeetleSearch):
    """The faithful algorithm of Sect. 1.3.1; all randomness from the injected generator.

    Attributes:
        objective: the objective g of Eq. (1.13) searched, with its scene and task.
        params: the step constants of Algorithm 1.
        rng: the generator of all the search's randomness (seed it for a reproducible run).
        rate: joint speed and acceleration limits; None: unlimited, as in the book.
        evaluations: objective evaluations so far.
        iterations: iterations of Algorithm 1 so far.
        infeasible: periods that ended outside Ω or whose limits could not all hold.
    """

    def iterate(
        self, q: np.ndarray, g: float, target: Target | np.ndarray, t: float
    ) -> tuple[np.ndarray, float]:
        """One iteration of Algorithm 1 from (q, g = g(q)); returns the accepted (q, g).

        Args:
            q: joint angles of the current iterate, shape (nq,) [rad].
            g: objective g(q) there (inf inside an obstacle).
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The accepted joint angles, shape (nq,) [rad], and their objective g.
        """
        return self._iterations(q, g, as_target(target), t, 1)

    def step(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray:
        """One control period: re-evaluate g for the new target, then iterate.

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles at the end of the period, shape (nq,) [rad].
        """
        target = as_target(target)
        obj, start = self.objective, q
        begun = self._begin_period(q, target, t)
        q, g = (q, obj.value(q, target, t)) if begun is None else begun
        q, g = self._iterations(q, g, target, t, self.params.iterations_per_step)
        q, g = self._smooth(start, q, g, target, t)
        return self._end_period(start, q, g)

    def _iterations(
        self, q: np.ndarray, g: float, target: Target, t: float, k: int
    ) -> tuple[np.ndarray, float]:
        """k iterations of Algorithm 1 from (q, g = g(q)): in one compiled call where the
        objective has its compiled evaluation, else one `_iteration` each; the draws are the
        same (the Generator fills rows in order). Returns the accepted (q, g)."""
        obj = self.objective
        self.evaluations += 3 * k
        self.iterations += k
        if obj.compiled is None:
            for _ in range(k):
                q, g = self._iteration(q, g, target, t, self.rng.standard_normal(q.size))
            return q, g
        directions = self.rng.standard_normal((k, q.size))
        problem = obj.problem(self._box, t, self._stop)
        p = self.params
        return kernel.iterations(q, g, obj.reference(target), directions, p.c1, p.c2, problem)

    def _iteration(
        self, q: np.ndarray, g: float, target: Target, t: float, b: np.ndarray
    ) -> tuple[np.ndarray, float]:
        """One iteration of Algorithm 1 in Python along the raw Gaussian draw b (the compiled
        kernel's reference); returns the accepted (q, g)."""
        obj, box, stop = self.objective, self._box, self._stop
        b = b / math.sqrt(b @ b)  # a normalised random direction
        lam = self.params.c1 * np.sqrt(g) if np.isfinite(g) else self.params.c1  # Eq. (1.23)
        # Eqs. (1.15)-(1.18): antennae, projected onto Ω, evaluated by "virtual robots".
        _, g_left = obj.project_and_value(q + lam * b, q, g, target, t, box, stop)
        _, g_right = obj.project_and_value(q - lam * b, q, g, target, t, box, stop)
        delta = self.params.c2 * lam  # Eq. (1.24)
        step = q - delta * np.sign(g_left - g_right) * b  # Eq. (1.19)
        q_new, g_new = obj.project_and_value(step, q, g, target, t, box, stop)  # Eq. (1.20)
        if g_new < g:  # Eqs. (1.21)-(1.22): accept only an improvement
            return q_new, g_new
        return q, g


def _turns(robot: RobotModel, offset: np.ndarray) -> np.ndarray:
    """The whole turns of a continuous joint in `offset` [rad] (exactly 0 elsewhere)."""
    return np.where(robot.continuous, 2 * np.pi * np.round(offset / (2 * np.pi)), 0.0)
