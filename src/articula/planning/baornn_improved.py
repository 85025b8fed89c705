"""BAORNN-improved: the faithful search with four changes, measured in the ch1 report.

1. Antenna length from the tracking term alone, λ_k = c1·√e_k, instead of c1·√g_k (1.23):
   with Λ > 0 the penalty keeps g_k ≥ Λ/d^β, so the faithful steps never shrink near the path
   and the arm jitters around it.
2. Several antenna pairs per iteration along orthonormal random directions; their differences
   estimate the gradient of g, and the step goes against that estimate instead of along one
   random direction; an antenna that already improves g is kept if the step does not.
3. A warm start each period: the last period's joint motion is repeated once, kept only if it
   improves g for the new reference point.
4. Antennae at two lengths: every second pair is `short_antenna` times as long. The long ones
   move the arm far enough to leave a poor posture; the short ones refine within a fraction of
   the error, which the long ones overshoot (with them alone the RMS error on the book's
   two-obstacle circle stays near 0.6 mm; with both, 0.25 mm: docs/deviations.md).
5. Tracking first: while the arm is at least `yield_distance` clear, no point with a larger
   task error than the period's start is accepted, so the penalty moves the arm through the
   redundancy only. The book's g trades error for clearance one to one (Λ/d² > 1 within
   √Λ = 71 mm for Λ = 0.005): with speed limits that trade drifted the arm into a posture
   whose joint limits leave no redundancy, ~20 mm off the path (docs/deviations.md).
6. Where the penalty is flat at the period's start (its slope Λβ/d^(β+1) below
   `flat_penalty_slope`, so that g is the task error for a step's purposes), a Gauss-Newton
   candidate after the warm start (planning/newton_step.py): the damped least-squares step on
   the task's own Jacobian, accepted like any other point.
7. Adaptive iterations: there, too, a period stops iterating once its accepted task error is
   below `quiet_error`. Where the penalty is steep neither applies: a step that ignores it
   drifts the arm into postures the penalty would have kept it out of (on the book's
   two-obstacle circle, Λ = 0.005, 3 of 10 seeds then end 4-12 mm off the path; none with
   the search alone: docs/deviations.md). Ω's hard bounds hold on every candidate.
8. Sliding along Ω's boundary: after the search, a period that ends off the path with a pair
   within `slide_reach` of its floor (d_min, or self_d_min between links, which the penalty
   does not see) tries one more candidate, the Gauss-Newton step on the task constrained to
   keep every such pair above its floor to first order (planning/slide.py). The antennae see
   the boundary only as points outside Ω; this step moves along it, the way the redundancy
   allows (issue 42, 100 grazing problems: 90 → 91 % on the iiwa14, 91 → 96 % on the
   Panda).
With acceleration limits the period's end is then smoothed as BAORNN's (planning/smooth.py),
change 5 kept there: while yield_distance clear, the smoothing's tracking term stiffens beyond
TRADE_CAP off the path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Annotated

import numpy as np
from pydantic import Field

from articula.planning import baornn_kernel as kernel
from articula.planning.baornn import BaornnParams, BeetleSearch
from articula.planning.clearance import ClearanceRows, EndEffector
from articula.planning.newton_step import newton_candidate, penalty_flat
from articula.planning.slide import SLIDE_MARGIN, slide_correction
from articula.planning.task import Target, as_target

# Off the path by this much [m], the smoothing's tracking term is as steep as g's; farther, it
# steepens, so that at least yield_distance clear the penalty trades little of the path.
TRADE_CAP = 5e-4


class ImprovedParams(BaornnParams):
    """BaornnParams with λ_k = c1·√e_k instead of (1.23), several and shorter antenna pairs.

    Attributes:
        c1: antenna length λ_k = c1·√e_k, e_k the task error (not Eq. 1.23's g_k) [rad/√m].
        c2: step δ_k = c2·λ_k, Eq. (1.24).
        iterations_per_step: iterations per control period.
        pairs: antenna pairs per iteration (at most the number of joints are used).
        short_antenna: length of every second pair relative to λ_k, in (0, 1].
        yield_distance: clearance below which a step may raise the task error; above it a
            period never does (change 5); inf: never capped, the book's acceptance [m].
        newton_damping: μ of the Gauss-Newton candidate (change 6); 0: none [m].
        quiet_error: task error below which a period stops iterating (change 7); 0: every
            period runs iterations_per_step [m].
        flat_penalty_slope: the penalty's slope below which changes 6 and 7 apply; 0: never
            (changes 1-5 alone) [-].
        slide_reach: how near its floor (d_min, self_d_min) a pair brings change 8's sliding
            step into play; 0: never [m].
        smoothing: "acceleration": each period ends at the least-acceleration descent of g
            from the search's point (planning/smooth.py); "none": at the search's point.
    """

    pairs: Annotated[int, Field(ge=1, le=64)] = 3
    short_antenna: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.25
    yield_distance: Annotated[float, Field(ge=0)] = 0.03
    newton_damping: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.02
    quiet_error: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 1e-5
    flat_penalty_slope: Annotated[float, Field(ge=0)] = 0.1
    slide_reach: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.01


@dataclass
class ImprovedBaornn(BeetleSearch):
    """Algorithm 1 with the changes above; the same objective, projection and acceptance.

    Attributes:
        objective: the objective g of Eq. (1.13) searched, with its scene and task.
        params: the step constants, with the antenna pairs.
        rng: the generator of all the search's randomness (seed it for a reproducible run).
        rate: joint speed and acceleration limits; None: unlimited, as in the book.
        evaluations: objective evaluations so far.
        iterations: iterations of Algorithm 1 so far.
        infeasible: periods that ended outside Ω or whose limits could not all hold.
    """

    params: ImprovedParams
    _last_motion: np.ndarray | None = field(default=None, init=False)

    def iterate(
        self, q: np.ndarray, g: float, target: Target | np.ndarray, t: float
    ) -> tuple[np.ndarray, float]:
        """One iteration from (q, g = g(q)); returns the accepted (q, g).

        Args:
            q: joint angles of the current iterate, shape (nq,) [rad].
            g: objective g(q) there (inf inside an obstacle).
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The accepted joint angles, shape (nq,) [rad], and their objective g.
        """
        p = self.params
        draw = self.rng.standard_normal((q.size, min(p.pairs, q.size)))
        return self._search(q, g, np.zeros(0), as_target(target), draw[None], t, period=False)

    def _iteration(
        self, q: np.ndarray, g: float, target: Target, draw: np.ndarray, t: float, cap: float
    ) -> tuple[np.ndarray, float]:
        """One iteration in Python from (q, g) with the Gaussian matrix `draw`, accepting no
        task error above `cap` (the compiled kernel's reference); returns the accepted (q, g)."""
        obj, p = self.objective, self.params
        model = obj.scene.robot.model
        box = self._box or (model.lowerPositionLimit, model.upperPositionLimit)
        # c1·√e_k, no longer than the box is wide (as the compiled kernel)
        lam = min(p.c1 * math.sqrt(obj.tracking_error(q, target)), kernel.antenna_cap(*box))
        # Orthonormal directions from a Gaussian matrix (columns), as many as pairs.
        directions = kernel._orthonormal_columns(draw)
        gradient = np.zeros(q.size)
        best_q, best_g = q, g
        for j, b in enumerate(directions):
            scale = kernel.antenna_scale(j, p.short_antenna)
            length = scale * lam
            # Eq. (1.15): the two antennae.
            q_left, g_left = obj.project_and_value(
                q + length * b, q, g, target, t, self._box, self._stop
            )
            q_right, g_right = obj.project_and_value(
                q - length * b, q, g, target, t, self._box, self._stop
            )
            if np.isfinite(g_left) and np.isfinite(g_right):
                # A difference over a shorter antenna counts as much per unit length.
                gradient += (g_left - g_right) / scale * b
            for q_a, g_a in ((q_left, g_left), (q_right, g_right)):
                if g_a < best_g and obj.tracking_error(q_a, target) <= cap:
                    best_q, best_g = q_a, g_a
        norm = math.sqrt(gradient @ gradient)
        self.evaluations += 2 * directions.shape[0]
        if norm > 0:
            step = q - p.c2 * lam * gradient / norm  # Eq. (1.19) along the estimated gradient
            q_new, g_new = obj.project_and_value(step, q, g, target, t, self._box, self._stop)
            self.evaluations += 1
            # Eqs. (1.21)-(1.22): only an improvement is accepted
            if g_new < best_g and obj.tracking_error(q_new, target) <= cap:
                best_q, best_g = q_new, g_new
        self.iterations += 1
        return best_q, best_g

    def reset(self) -> None:
        """Forget the previous periods: no warm start, the arm at rest."""
        super().reset()
        self._last_motion = None

    def follow(self, motion: np.ndarray) -> None:
        """Take the arm's measured joint motion [rad] over the period that ended as its motion:
        the next period's limits and warm start start from it.

        Args:
            motion: the measured joint displacement over the last period, shape (nq,) [rad].
        """
        super().follow(motion)
        self._last_motion = np.array(motion, dtype=float)

    def step(self, q: np.ndarray, target: Target | np.ndarray, t: float) -> np.ndarray:
        """One control period: warm start, then iterate.

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target, or a position, shape (3,) [m].
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles at the end of the period, shape (nq,) [rad].
        """
        target = as_target(target)
        start = q
        p = self.params
        # With limits the period starts where braking as hard as they allow takes it, and
        # coasting, q plus the last motion, is the warm start (g = inf outside Ω).
        warm = self._last_motion
        if self._limit_period(q):
            q = np.clip(q, *self._box)
            warm = None if warm is None else start + warm - q
        # The same draws as iterations_per_step calls of iterate.
        draws = self.rng.standard_normal((p.iterations_per_step, q.size, min(p.pairs, q.size)))
        warm = np.zeros(0) if warm is None else warm
        q, g = self._search(q, math.nan, warm, target, draws, t, period=True)
        if p.slide_reach > 0:
            q, g = self._slide(q, g, target, t)
        q, g = self._smooth(start, q, g, target, t)
        self._last_motion = q - start
        return self._end_period(start, q, g)

    def _search(
        self,
        q: np.ndarray,
        g: float,
        warm: np.ndarray,
        target: Target,
        draws: np.ndarray,
        t: float,
        period: bool,
    ) -> tuple[np.ndarray, float]:
        """From q with g = g(q) (NaN: computed there, inf outside Ω), a warm start (none when
        `warm` is empty), for a whole `period` the Gauss-Newton candidate and the quiet stop
        (changes 6 and 7), and one iteration per matrix of `draws`: in one compiled call
        (planning/baornn_kernel.py) where the objective has its compiled evaluation, else in
        Python; moving obstacles at time t. Returns the accepted (q, g)."""
        obj, p = self.objective, self.params
        damping, quiet, flat_slope = (
            (p.newton_damping, p.quiet_error, p.flat_penalty_slope) if period else (0.0, 0.0, 0.0)
        )
        if obj.compiled is not None:
            q, g, evaluations, run = kernel.improved_period(
                q,
                g,
                warm,
                obj.reference(target),
                draws,
                p.c1,
                p.c2,
                p.short_antenna,
                p.yield_distance,
                damping,
                quiet,
                flat_slope,
                obj.problem(self._box, t, self._stop),
            )
            self.evaluations += evaluations
            self.iterations += run
            return q, g
        if math.isnan(g):  # g at q, inf outside Ω: any point inside it is better
            g = obj.project_and_value(q, q, math.inf, target, t, (q, q), self._stop)[1]
        d = obj.evaluation.measure(q, t, obj.needs_obstacles, False)[0]
        cap = kernel.tracking_cap(obj.tracking_error(q, target), g, d, p.yield_distance)
        flat = penalty_flat(d, obj.lambda_weight, obj.beta, flat_slope)
        if warm.size:
            q_warm, g_warm = obj.project_and_value(q + warm, q, g, target, t, self._box, self._stop)
            self.evaluations += 1
            if g_warm < g and obj.tracking_error(q_warm, target) <= cap:
                q, g = q_warm, g_warm
        if flat and damping > 0:
            q_gn, g_gn = obj.project_and_value(
                self._newton(q, target, damping), q, g, target, t, self._box, self._stop
            )
            self.evaluations += 1
            if g_gn < g and obj.tracking_error(q_gn, target) <= cap:
                q, g = q_gn, g_gn
        for draw in draws:
            if flat and obj.tracking_error(q, target) < quiet:
                break  # on the path (change 7)
            q, g = self._iteration(q, g, target, draw, t, cap)
        return q, g

    def _slide(self, q: np.ndarray, g: float, target: Target, t: float) -> tuple[np.ndarray, float]:
        """Change 8: from the period's accepted (q, g), off the path and within slide_reach of
        a floor, the Gauss-Newton step on the task that keeps every pair near its floor above
        it to first order (planning/slide.py), projected onto Ω (1.17) with the braking check
        and kept only if it lowers g and the task error; returns the accepted (q, g)."""
        obj, p = self.objective, self.params
        error = obj.tracking_error(q, target)
        if error <= p.quiet_error or not math.isfinite(g):
            return q, g
        floors = (obj.d_min, obj.self_d_min)
        reach = max(floors) + SLIDE_MARGIN + p.slide_reach
        end, rows = self._rows(q, t, reach)
        floor = np.where(rows.self_pair, floors[1], floors[0])
        if not np.any(rows.distance < floor + p.slide_reach):
            return q, g  # nothing near its floor: the search alone decides
        A, residual = self._task_rows(end, target)
        model = obj.scene.robot.model
        low, high = self._box or (model.lowerPositionLimit, model.upperPositionLimit)
        step = slide_correction(
            rows, floors, low - q, high - q, A, residual, p.newton_damping**2, p.slide_reach
        )
        self.evaluations += 1
        if step is None:
            return q, g
        q_s, g_s = obj.project_and_value(q + step, q, g, target, t, self._box, self._stop)
        if g_s < g and obj.tracking_error(q_s, target) < error:
            return q_s, g_s
        return q, g

    def _error_cap(self, rows: ClearanceRows) -> float:
        """Change 5 in the smoothing: at least yield_distance clear, the penalty trades no
        more than TRADE_CAP of the task for clearance [m]; closer, as g does."""
        obstacle = rows.distance[~rows.self_pair]
        if obstacle.size and obstacle.min() < self.params.yield_distance:
            return math.inf
        return TRADE_CAP

    def _newton(self, q: np.ndarray, target: Target, damping: float) -> np.ndarray:
        """The Gauss-Newton candidate from q [rad] (change 6), Pinocchio's Jacobian."""
        robot = self.objective.scene.robot
        pose = robot.ee_pose(q)
        end = EndEffector(pose[:3, 3].copy(), pose[:3, :3].copy(), robot.jacobian(q))
        A, residual = self._task_rows(end, target)
        box = self._box or (robot.model.lowerPositionLimit, robot.model.upperPositionLimit)
        return newton_candidate(q, A, residual, damping, *box)
