"""Beyond the book: coordinate descent on the pulse that minimises settling, in any direction.

Chapter 2's Algorithm 1 (`tuning.coordinate_descent`) on the simulated settling time of the
true angle, from fixed starting points.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from articula.book.ch3.what_ifs import BOOK_PULSE, IDEAL, Outcome, outcome
from articula.control.damping import DampingPolicy
from articula.experiments.six_chamber import DeactuationConfig, run_metrics, simulate_deactuation
from articula.tuning.coordinate_descent import DescentResult, coordinate_descent

Curve = tuple[np.ndarray, np.ndarray]
TIMED = ("delta", "start", "length")  # the pulse's parameters, in the searches' order
K_STOP = 0.005  # stop when |dK|_1 falls below this
DELTA_MAX = 0.95  # DampingPolicy's bound on δ
TIMING_MAX = 1.0  # [s] upper bound of start and length
BOOK_K0, BOOK_DK0 = (0.3,), (0.1,)  # δ alone, book timing
TIMED_K0, TIMED_DK0 = (0.3, 0.1, 0.08), (0.1, 0.03, 0.03)  # δ, start [s], length [s]
SIDE_DEG = 30.0  # [deg] the side between chambers 0 and 1 searched on its own
SIDES = (0.0, 30.0, 60.0, 105.0)  # [deg] sides the side-0° pulse is applied to
PulseKind = Literal["none", "side 0", "own"]


@dataclass(frozen=True)
class Pulse:
    """A pulse found by a search: its policy, the settling it reached [s] and its cost.

    Attributes:
        policy: the damping policy at the search's best point.
        searched: the policy's fields the search moved.
        settling_s: settling time [s] of the true angle at the best point.
        evaluations: cost evaluations the search made.
        peak_deg: peak past rest [deg] at the best point (None: not evaluated).
    """

    policy: DampingPolicy
    searched: tuple[str, ...]
    settling_s: float
    evaluations: int
    peak_deg: float | None = None

    def data(self) -> dict[str, Any]:
        """The searched parameters, settling_s, peak_deg (if evaluated) and evaluations."""
        values: dict[str, Any] = {n: getattr(self.policy, n) for n in self.searched}
        values["settling_s"] = self.settling_s
        if self.peak_deg is not None:
            values["peak_deg"] = self.peak_deg
        return {**values, "evaluations": self.evaluations}


@dataclass(frozen=True)
class DirectionRow:
    """One pressurised side [deg] with no pulse, the side-0° pulse or the side's own pulse."""

    side_deg: float
    pulse: PulseKind
    outcome: Outcome


@dataclass(frozen=True)
class Directions:
    """The side-0° pulse applied to other sides, and the pulse found for SIDE_DEG."""

    rows: tuple[DirectionRow, ...]
    own: Pulse


def settling_cost(delta: float, start: float, length: float, side_deg: float = 0.0) -> float:
    """Settling time [s] of the true angle for one pulse (the run length if it never settles)."""
    config = DeactuationConfig(
        side_deg=side_deg,
        sensor=IDEAL,
        damping=DampingPolicy(delta=delta, start=start, length=length),
    )
    s = run_metrics(simulate_deactuation(config), config.band_deg)["settling_true_s"]
    return config.after if math.isnan(s) else s


def _descend(
    cost: Callable[[np.ndarray], float],
    k0: tuple[float, ...],
    dk0: tuple[float, ...],
    iterations: int,
) -> DescentResult:
    """Coordinate descent within [0, DELTA_MAX] for δ and [0, TIMING_MAX] for the timing."""
    upper = np.array([DELTA_MAX, TIMING_MAX, TIMING_MAX][: len(k0)])
    return coordinate_descent(
        cost, np.array(k0), np.array(dk0), K_STOP, iterations, lower=np.zeros(len(k0)), upper=upper
    )


def _pulse(result: DescentResult, names: tuple[str, ...], peak: bool = True) -> Pulse:
    """The Pulse at a search's best point, with its peak [deg] simulated if `peak`."""
    policy = DampingPolicy(**dict(zip(names, (float(v) for v in result.k), strict=True)))
    peak_deg = outcome(policy).peak_deg if peak else None
    return Pulse(policy, names, float(result.cost), result.evaluations, peak_deg)


def book_timing(iterations: int) -> Pulse:
    """The δ that minimises settling with the book's timing (at the vent command, brief)."""
    found = _descend(lambda k: settling_cost(k[0], 0.0, 0.0), BOOK_K0, BOOK_DK0, iterations)
    return _pulse(found, TIMED[:1])


def timed(iterations: int) -> Pulse:
    """The δ, start [s] and length [s] that minimise settling."""
    return _pulse(_descend(lambda k: settling_cost(*k), TIMED_K0, TIMED_DK0, iterations), TIMED)


def directions(policy: DampingPolicy, iterations: int) -> Directions:
    """`policy` (found for side 0°) on SIDES, and a search for SIDE_DEG started from it."""
    start = (policy.delta, policy.start, policy.length)
    found = _descend(lambda k: settling_cost(*k, side_deg=SIDE_DEG), start, TIMED_DK0, iterations)
    own = _pulse(found, TIMED, peak=False)
    cases: list[tuple[float, PulseKind, DampingPolicy]] = [
        (s, "none", DampingPolicy()) for s in SIDES
    ]
    cases += [(s, "side 0", policy) for s in SIDES]
    cases += [(SIDE_DEG, "own", own.policy)]
    rows = tuple(
        DirectionRow(side, kind, outcome(damping, side_deg=side))
        for side, kind, damping in sorted(cases, key=lambda c: c[0])
    )
    return Directions(rows, own)


def pulse_curves(
    policies: Mapping[str, DampingPolicy],
) -> tuple[dict[str, Curve], dict[str, Curve]]:
    """Bending angle [deg] and the opposite chamber's gauge pressure [kPa] after the vent
    command (time [s]) for each named policy."""
    curves, pressures = {}, {}
    for label, policy in policies.items():
        config = DeactuationConfig(sensor=IDEAL, damping=policy)
        run = simulate_deactuation(config)
        after = run.sim.t >= config.hold
        t = run.sim.t[after] - config.hold
        curves[label] = (t, np.degrees(run.sim.beta[after] @ run.direction))
        pressures[label] = (t, run.sim.gauge[after, 3] / 1e3)
    return curves, pressures


def compared(book: Pulse, best: Pulse) -> dict[str, DampingPolicy]:
    """The policies the best-pulse figure compares, by label."""
    return {
        "undamped": DampingPolicy(),
        "book pulse, δ = 0.5": BOOK_PULSE,
        "best δ, book timing": book.policy,
        "best δ and timing": best.policy,
    }
