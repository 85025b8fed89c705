"""What the resolved-rate planners (pinv, dls, qp) share: the period's reachable box from the
joint speed, acceleration and position limits, the measured motion, and a check that a step
keeps d_min and self_d_min."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from articula.planning.clearance import ClearanceRows, RowSource
from articula.planning.planner import WARM_UP_STEPS
from articula.planning.rate_limits import RateLimits, braking_path
from articula.planning.reference_velocity import task_rows
from articula.planning.slide import SLIDE_BAND, SLIDE_MARGIN, slide_correction
from articula.planning.task import Target, Task, as_target
from articula.robots.sweep import joint_sweep
from articula.scene.scene import Scene

BACKTRACKS = 3  # halvings of a step that breaks a clearance before the arm brakes instead
SLIDES = 3  # corrections of a step back onto the feasible side before it is halved
# The (link-obstacle, self) clearance lost per metre a point of the arm moves at most: a link
# pair's distance shrinks by both links' motions.
PAIR_SWEEP = np.array([1.0, 2.0])


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
    _task_jacobian: np.ndarray = field(init=False, repr=False)  # this period's task rows
    _sweep: np.ndarray = field(init=False, repr=False)  # robots.sweep.joint_sweep [m/rad]

    def __post_init__(self) -> None:
        self._rows = RowSource(self.scene, self.use_compiled)
        self._sweep = joint_sweep(self.scene.robot)
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
        self._task_jacobian = J
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
        grow), else slid back onto the feasible side of the boundary it crossed (its motion
        along that boundary kept), else halved toward braking, else braking (counted as
        infeasible); the motion remembered for the acceleration limit."""
        q_new = np.clip(q_new, *box)
        if rows.distance.size:  # something is within the influence distance: check the step
            q_new, held = self._clear_step(q, q_new, box, t)
            strained = strained or not held
        if strained or self._limits.strained:
            self.infeasible += 1
        self._limits.record(q_new - q)
        return q_new

    def _clear_step(
        self, q: np.ndarray, q_new: np.ndarray, box: tuple[np.ndarray, np.ndarray], t: float
    ) -> tuple[np.ndarray, bool]:
        """(q_new, or q_new slid onto the feasible side of the floors it crosses (up to SLIDES
        corrections, planning/slide.py), or the first of its halvings toward braking, or braking
        itself, whose clearances, there and along braking from it (_clearances_braking), are
        above d_min and self_d_min or no lower than at q; whether one was)."""
        floors = self._floors
        now = None
        candidate = q_new
        for k in range(SLIDES + 1):
            clear = self._clearances_braking(q, candidate, t)
            if np.all(clear > floors):
                return candidate, True
            if now is None:
                now = self._clearances(q, t)
            if np.all((clear > floors) | (clear >= now)):
                return candidate, True
            correction = None if k == SLIDES else self._slide(q, candidate, box, t)
            if correction is None:
                break
            candidate = candidate + correction
        brake = np.clip(q, *box)
        for k in range(1, BACKTRACKS + 1):
            candidate = brake + 0.5**k * (q_new - brake)
            clear = self._clearances_braking(q, candidate, t)
            if np.all((clear > floors) | (clear >= now)):
                return candidate, True
        clear = self._clearances_braking(q, brake, t)
        return brake, bool(np.all((clear > floors) | (clear >= now)))

    def _slide(
        self, q: np.ndarray, q_new: np.ndarray, box: tuple[np.ndarray, np.ndarray], t: float
    ) -> np.ndarray | None:
        """The correction [rad] that puts q_new, and where braking from it ends, back above
        the floors to first order within the box (slide_correction); None when none does."""
        floors = self._floors
        reach = max(floors) + SLIDE_MARGIN + SLIDE_BAND
        _, rows = self._rows(q_new, t, reach)
        points = self._braking_points(q, q_new)
        if len(points):  # where braking ends
            _, at_end = self._rows(points[-1], t, reach)
            rows = ClearanceRows(
                np.concatenate([rows.distance, at_end.distance]),
                np.vstack([rows.gradient, at_end.gradient]),
                np.concatenate([rows.self_pair, at_end.self_pair]),
            )
        low, high = box[0] - q_new, box[1] - q_new
        correction = slide_correction(rows, floors, low, high, self._task_jacobian)
        if correction is None or not np.any(correction):
            return None
        return correction

    def _clearances_braking(self, q: np.ndarray, q_new: np.ndarray, t: float) -> np.ndarray:
        """(link-obstacle, self) clearance [m]: the smaller of q_new's and, with acceleration
        limits, of the points braking from the motion q → q_new passes (_braking_points),
        each measured where the room above the floors left since the last measured one could
        be used up (a motion Δq moves no point farther than Σ sweep_j |Δq_j|, so no link
        pair's distance more than twice that), as baornn_kernel.stoppable does."""
        clear = self._clearances(q_new, t)
        points = self._braking_points(q, q_new)
        floors = self._floors
        lowest, before = clear, q_new
        room = np.min((clear - floors) / PAIR_SWEEP)
        for point in points:
            room -= self._sweep @ np.abs(point - before)
            before = point
            if room <= 0.0:
                measured = self._clearances(point, t)
                lowest = np.minimum(lowest, measured)
                room = np.min((measured - floors) / PAIR_SWEEP)
        return lowest

    def _braking_points(self, q: np.ndarray, q_new: np.ndarray) -> np.ndarray:
        """Where each period of braking as hard as the limits allow from the motion q → q_new
        ends (rate_limits.braking_path) [rad], shape (periods, nq); none without acceleration
        limits. Every period, not only where it stops: the joints stop at different times, and
        the clearance between can be lower than at either end."""
        limits = self._limits
        if limits.change is None:
            return np.zeros((0, q.size))
        last = np.zeros_like(q) if limits.last_motion is None else limits.last_motion
        jerk = np.zeros(0) if limits.jerk_change is None else limits.jerk_change
        return q_new + braking_path(q_new - q, last, limits.change, jerk)

    @property
    def _floors(self) -> np.ndarray:
        """(d_min, self_d_min): the floors of link-obstacle and link-link clearance [m]."""
        return np.array([self.d_min, self.scene.self_d_min])

    def _clearances(self, q: np.ndarray, t: float) -> np.ndarray:
        """(link-obstacle, self) clearance at q [m], compiled where the scene allows it."""
        d, d_self, _, _ = self._rows.evaluation.measure(q, t, True, True)
        return np.array([d, d_self])
