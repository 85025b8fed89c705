"""What the resolved-rate planners (pinv, dls, qp) share: the period's reachable box from the
joint speed, acceleration and position limits, the measured motion, and a check that a step
keeps d_min and self_d_min."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from articula.planning.clearance import ClearanceRows, RowSource
from articula.planning.planner import WARM_UP_STEPS
from articula.planning.rate_limits import RateLimits, braking_after
from articula.planning.reference_velocity import task_rows
from articula.planning.task import Target, Task, as_target
from articula.scene.scene import Scene

BACKTRACKS = 3  # halvings of a step that breaks a clearance before the arm brakes instead


@dataclass
class ResolvedRate(ABC):
    """A base for the resolved-rate planners: the scene, the clearance they keep, their task
    and limits, their counts, and what each period starts with (the reachable box, the rows
    near an obstacle, the task's rows) and ends with (the clearance check).

    A subclass declares its own `dt` and `params` (with `influence`, `gain` and
    `speed_scale`) and its `step`.

    Attributes:
        scene: the robot, its obstacles and its checked link pairs.
        d_min: hard minimum clearance (Eq. 1.12) the start and every step keep [m].
        task: what the end effector tracks.
        use_compiled: take distances and kinematics from CompiledClearance where possible.
        rate: joint speed and acceleration limits; None: the URDF's speeds times
            params.speed_scale.
        iterations: control periods computed so far.
        infeasible: periods that braked because no motion kept the clearances, or whose
            limits could not all hold.
    """

    scene: Scene
    d_min: float = field(default=0.0, kw_only=True)
    task: Task = field(default_factory=Task, kw_only=True)
    use_compiled: bool = field(default=True, kw_only=True)
    rate: RateLimits | None = field(default=None, kw_only=True)
    iterations: int = field(default=0, init=False)
    infeasible: int = field(default=0, init=False)
    _previous: Target | None = field(default=None, init=False, repr=False)
    _rows: RowSource = field(init=False, repr=False)
    _limits: RateLimits = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._rows = RowSource(self.scene, self.use_compiled)
        if self.rate is None:
            speeds = self.scene.robot.velocity_limit
            self._limits = RateLimits(
                self.params.speed_scale * np.where(speeds > 0, speeds, np.inf), self.dt
            )
        else:
            self._limits = self.rate

    def reset(self) -> None:
        """Forget the previous target and motion: no feed-forward, the arm at rest."""
        self._previous = None
        self._limits.reset()

    def follow(self, motion: np.ndarray) -> None:
        """Take the arm's measured joint motion [rad] over the period that ended as its motion:
        the next period's limits hold relative to it.

        Args:
            motion: the measured joint displacement over the last period, shape (nq,) [rad].
        """
        self._limits.record(motion)

    def warm_up(self, q: np.ndarray, target: Target) -> None:
        """Compile (or load) the kernels of a step, and of its clearance check, by taking
        WARM_UP_STEPS of them (the interpreter specialises what runs a few times); the counts
        are put back (reset() forgets the steps' motion).

        Args:
            q: a configuration to step from, shape (nq,) [rad].
            target: a target to step toward.
        """
        counts = (self.iterations, self.infeasible)
        for _ in range(WARM_UP_STEPS):
            self.step(q.copy(), target, 0.0)
        self._clearances(q, 0.0)
        self.iterations, self.infeasible = counts

    @abstractmethod
    def step(self, q: np.ndarray, target: Target, t: float) -> np.ndarray:
        """One control period (the subclass's).

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target.
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles after dt, shape (nq,) [rad].
        """

    def _begin(
        self, q: np.ndarray, target: Target | np.ndarray, t: float
    ) -> tuple[tuple[np.ndarray, np.ndarray], ClearanceRows, np.ndarray, np.ndarray]:
        """What a period starts with at q [rad]: (the box it can reach, the clearance rows
        within the influence distance, the task Jacobian and the task velocity it asks for);
        the target is remembered for the next period's feed-forward."""
        target = as_target(target)
        box = self._box(q)
        ee, rows = self._rows(q, t, self.params.influence)
        J, v = task_rows(
            ee.x, ee.R, ee.J, self.task, target, self._previous, self.dt, self.params.gain
        )
        self._previous = target
        return box, rows, J, v

    def _box(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The configurations this period can reach from q [rad] within every limit."""
        robot = self.scene.robot
        return self._limits.box(q, robot.lower, robot.upper)

    def _finish(
        self,
        q: np.ndarray,
        q_new: np.ndarray,
        box: tuple[np.ndarray, np.ndarray],
        rows: ClearanceRows,
        t: float,
        strained: bool = False,
    ) -> np.ndarray:
        """The period's configuration: q_new within the box, kept if its clearances hold (or
        grow), else halved toward braking, else braking (counted as infeasible); the motion
        remembered for the acceleration limit."""
        q_new = np.clip(q_new, *box)
        if rows.distance.size:  # something is within the influence distance: check the step
            q_new, held = self._clear_step(q, q_new, np.clip(q, *box), t)
            strained = strained or not held
        if strained or self._limits.strained:
            self.infeasible += 1
        self._limits.record(q_new - q)
        return q_new

    def _clear_step(
        self, q: np.ndarray, q_new: np.ndarray, brake: np.ndarray, t: float
    ) -> tuple[np.ndarray, bool]:
        """(the first of q_new, its halvings toward `brake`, `brake` itself whose clearances,
        there and where braking from it ends, are above d_min and self_d_min or no lower than
        at q; whether one was)."""
        floors = np.array([self.d_min, self.scene.self_d_min])
        now = None
        candidate = q_new
        for k in range(BACKTRACKS + 2):
            if k == BACKTRACKS + 1:
                candidate = brake
            clear = self._clearances_braking(q, candidate, t)
            if np.all(clear > floors):
                return candidate, True
            if now is None:
                now = self._clearances(q, t)
            if np.all((clear > floors) | (clear >= now)):
                return candidate, True
            candidate = brake + 0.5 * (candidate - brake)
        return brake, False

    def _clearances_braking(self, q: np.ndarray, q_new: np.ndarray, t: float) -> np.ndarray:
        """(link-obstacle, self) clearance [m] at q_new and, with acceleration limits, at the
        point where braking from the motion q → q_new ends: the smaller of the two."""
        clear = self._clearances(q_new, t)
        change = self._limits.change
        if change is not None:
            limits = self._limits
            last = np.zeros_like(q) if limits.last_motion is None else limits.last_motion
            jerk = np.zeros(0) if limits.jerk_change is None else limits.jerk_change
            end = q_new + braking_after(q_new - q, last, change, jerk)
            clear = np.minimum(clear, self._clearances(end, t))
        return clear

    def _clearances(self, q: np.ndarray, t: float) -> np.ndarray:
        """(link-obstacle, self) clearance at q [m], compiled where the scene allows it."""
        d, d_self, _, _ = self._rows.evaluation.measure(q, t, True, True)
        return np.array([d, d_self])
