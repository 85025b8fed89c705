"""Chapter 3's results as numbers and claims: pure functions of the sweeps and the what-ifs."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from articula.book.ch3.book_values import (
    BOOK_DAMPED_PEAK_DEG,
    BOOK_DAMPED_SETTLING_S,
    BOOK_DELTA,
    BOOK_SAYS,
    CLAIM_BOOK,
    CLAIM_GROWS,
)
from articula.book.ch3.searches import DirectionRow
from articula.book.ch3.study import Ch3Results, DeltaSweep, TimingSweep
from articula.book.ch3.what_ifs import ActuatorModel, StiffeningRow, ValveCase
from articula.book.claims import Claim, decide
from articula.book.text import fixed
from articula.plants.six_chamber import DATASHEET_MODULUS

# "Damping grows": peak and settling non-increasing in δ within sensor-level noise, and the
# largest δ at most HALVED times the undamped peak.
PEAK_TOL = 0.1  # [deg]
SETTLE_TOL = 0.02  # [s]
HALVED = 0.5
# "About 2° and 0.5 s": a peak of at most 3° (one-sided: less is better) and settling within
# ±0.15 s of 0.5 s, at a swept δ within 0.05 of the book's 0.5.
BOOK_PEAK_MAX_DEG = 3.0
BOOK_SETTLING_TOL_S = 0.15
DELTA_TOL = 0.05
SOLENOID_S = 0.010  # [s] open times below this are shorter than a solenoid's 5-20 ms switching
SIMILAR = 1.5  # between chambers "does about as well" if it settles within this factor


@dataclass(frozen=True)
class TimingSummary:
    """Notable pulses of the timing grid, as indices into the timing sweep.

    Attributes:
        best: shortest settling.
        calm: shortest settling among pulses that do not raise the undamped peak.
        early: the first start with the longest length (the book's timing held longer).
        lowest_peak_deg: lowest peak past rest on the grid [deg].
    """

    best: int
    calm: int
    early: int
    lowest_peak_deg: float


@dataclass(frozen=True)
class Findings:
    """The numbers and verdicts the report states beside the results.

    Attributes:
        period_s: the body's natural period [s].
        body_overshoot: overshoot the body's own damping alone would leave.
        modulus_fraction: calibrated E over the datasheet modulus.
        datasheet_pressure: chamber pressure a beam of datasheet modulus needs for the same
            bend [Pa].
        too_fast: for each δ of Fig. 3.7, whether its open time is below SOLENOID_S.
        sensitivity_holds: no changed valve constant lets the book's pulse meet the book.
        reduction: fractional drop of the sensor's peak at the mechanism's δ.
        fastest: index of the shortest settling of Fig. 3.7.
        open_ms: shortest and longest non-zero open time of Fig. 3.7 [ms] (None: no pulse).
        grows: the "damping grows" claim holds.
        stiffening_helps: some stiffening lets a pulse halve the peak.
        timing: the timing grid's summary.
        similar: the side-0° pulse does about as well between chambers.
    """

    period_s: float
    body_overshoot: float
    modulus_fraction: float
    datasheet_pressure: float
    too_fast: list[bool]
    sensitivity_holds: bool
    reduction: float
    fastest: int
    open_ms: tuple[float, float] | None
    grows: bool
    stiffening_helps: bool
    timing: TimingSummary
    similar: bool


def _inf(values: Sequence[float | None]) -> np.ndarray:
    """Values with None as +inf (a missing peak or settling counts as the worst)."""
    return np.array([np.inf if x is None else x for x in values], dtype=float)


def damping_grows(peak_deg: Sequence[float | None], settling_s: Sequence[float | None]) -> bool:
    """Peak [deg] and settling [s] non-increasing in δ within PEAK_TOL and SETTLE_TOL, and the
    last peak at most HALVED times the first."""
    p, s = _inf(peak_deg), _inf(settling_s)
    return bool(
        np.all(np.diff(p) <= PEAK_TOL)
        and np.all(np.diff(s) <= SETTLE_TOL)
        and p[-1] <= HALVED * p[0]
    )


def meets_book(peak_deg: float, settling_s: float) -> bool:
    """Peak [deg] at most BOOK_PEAK_MAX_DEG and settling [s] within BOOK_SETTLING_TOL_S of the
    book's (NaN settling: no)."""
    off = abs(settling_s - BOOK_DAMPED_SETTLING_S)
    return peak_deg <= BOOK_PEAK_MAX_DEG and off <= BOOK_SETTLING_TOL_S


def nearest_book_delta(delta: Sequence[float]) -> int:
    """Index of the swept δ nearest the book's."""
    return int(np.argmin(np.abs(np.array(delta) - BOOK_DELTA)))


def claims(sweep: DeltaSweep) -> list[Claim]:
    """The two claims of Sect. 3.4, decided by the Fig. 3.7 sweep."""
    p, s = _inf(sweep.peak_deg), _inf(sweep.settling_s)
    near = nearest_book_delta(sweep.delta)
    close = abs(sweep.delta[near] - BOOK_DELTA) <= DELTA_TOL
    return [
        decide(
            CLAIM_GROWS,
            BOOK_SAYS[CLAIM_GROWS],
            f"peak {fixed(p[0], 2)}° → {fixed(p[-1], 2)}°, settling {fixed(s[0], 3)} s → "
            f"{fixed(s[-1], 3)} s from δ = {sweep.delta[0]:g} to {sweep.delta[-1]:g}",
            f"peak and settling non-increasing in δ within {PEAK_TOL}° and {SETTLE_TOL} s, and "
            f"the peak at the largest δ at most {HALVED:g} times the one at the smallest; "
            "inconclusive with fewer than two δ",
            damping_grows(sweep.peak_deg, sweep.settling_s) if len(sweep.delta) > 1 else None,
        ),
        decide(
            CLAIM_BOOK,
            BOOK_SAYS[CLAIM_BOOK],
            f"at δ = {sweep.delta[near]:g}: peak {fixed(p[near], 2)}°, settling "
            f"{fixed(s[near], 3)} s",
            f"at a swept δ within {DELTA_TOL} of {BOOK_DELTA}, peak ≤ {BOOK_PEAK_MAX_DEG:g}° "
            f"(book {BOOK_DAMPED_PEAK_DEG:g}°) and settling within {BOOK_SETTLING_TOL_S} s of "
            f"{BOOK_DAMPED_SETTLING_S} s; inconclusive without such a δ",
            meets_book(p[near], s[near]) if close else None,
        ),
    ]


def period(model: ActuatorModel) -> float:
    """The body's natural period 2π/ω_n [s]."""
    return 2 * math.pi / model.natural_frequency


def body_overshoot(zeta: float) -> float:
    """Overshoot exp(−πζ/√(1 − ζ²)) of a second-order system released from a bend."""
    return math.exp(-math.pi * zeta / math.sqrt(1 - zeta**2))


def sensitivity_holds(cases: Sequence[ValveCase]) -> bool:
    """No changed valve constant lets the book's pulse give about 2° and 0.5 s."""
    return not any(meets_book(c.pulse.peak_deg, c.pulse.settling_s) for c in cases)


def stiffening_helps(rows: Sequence[StiffeningRow]) -> bool:
    """Some stiffening lets a run reach HALVED times its row's no-pulse peak."""
    return any(o.peak_deg <= HALVED * r.outcomes[0].peak_deg for r in rows for o in r.outcomes)


def timing_summary(timing: TimingSweep, undamped_peak_deg: float) -> TimingSummary:
    """The timing grid's best, calmest and book-like pulses against the undamped peak [deg]."""
    settle, peak = timing.settling_s, timing.peak_deg
    best = int(np.nanargmin(settle))
    keeps = np.nonzero(peak <= undamped_peak_deg + PEAK_TOL)[0]
    calm = int(keeps[np.nanargmin(settle[keeps])]) if keeps.size else best
    early = (timing.start == timing.start.min()) & (timing.length == timing.length.max())
    return TimingSummary(best, calm, int(np.nonzero(early)[0][0]), float(np.nanmin(peak)))


def similar_between_chambers(rows: Sequence[DirectionRow]) -> bool:
    """The side-0° pulse settles between chambers within SIMILAR times its best on a chamber."""
    pulsed = [r for r in rows if r.pulse == "side 0"]
    single = [r.outcome.settling_s for r in pulsed if r.side_deg % 60 == 0]
    between = [r.outcome.settling_s for r in pulsed if r.side_deg % 60 != 0]
    return max(between) <= SIMILAR * min(single)


def findings(r: Ch3Results) -> Findings:
    """Every derived number and verdict the report states."""
    p, sweep = r.model.params, r.delta
    peak = _inf(sweep.peak_deg)
    opens = [1e3 * t for t in sweep.open_s if t > 0]
    return Findings(
        period_s=period(r.model),
        body_overshoot=body_overshoot(r.model.damping_ratio),
        modulus_fraction=p.youngs_modulus / DATASHEET_MODULUS,
        datasheet_pressure=DATASHEET_MODULUS / p.youngs_modulus * p.supply,
        too_fast=[0 < t < SOLENOID_S for t in sweep.open_s],
        sensitivity_holds=sensitivity_holds(r.sensitivity),
        reduction=1 - peak[sweep.delta.index(r.mechanism.delta)] / peak[0],
        fastest=int(np.nanargmin(_inf(sweep.settling_s))),
        open_ms=(min(opens), max(opens)) if opens else None,
        grows=damping_grows(sweep.peak_deg, sweep.settling_s),
        stiffening_helps=stiffening_helps(r.stiffening),
        timing=timing_summary(r.timing, r.model.undamped.peak_deg),
        similar=similar_between_chambers(r.directions.rows),
    )
