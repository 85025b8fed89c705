"""Manual tuning of Sect. 2.3.2.1 as a scripted procedure, and the Ziegler-Nichols table.

The procedure decides from each step response only, as an operator watching the rig would:
raise K_p (K_i = K_d = 0) until the response oscillates and the swings die out; then raise
K_i until the steady-state error is within tolerance; then raise K_d while it lowers the
overshoot without adding swings. Every experiment is kept, for Fig. 2.5.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from articula.errors import ConfigError, InfeasibleError
from articula.tuning.response import (
    GainExperiment,
    Response,
    StepFeatures,
    readonly,
    step_features,
)
from articula.validation import Positive, StrictModel, field_error


class Ladder(StrictModel):
    """Values tried in turn: start, start·factor, ... up to at most `stop` (a gain's unit).

    Attributes:
        start: first value tried, > 0.
        factor: ratio between successive values, in (1, 1000].
        stop: largest value that may be tried, at least start.
    """

    start: Positive
    factor: Annotated[float, Field(gt=1, le=1e3, allow_inf_nan=False)]
    stop: Positive

    @model_validator(mode="after")
    def _ordered(self) -> Ladder:
        if self.stop < self.start:
            raise field_error("stop", f"must be at least start = {self.start} (got {self.stop})")
        return self

    def values(self) -> list[float]:
        """The rungs, smallest first.

        Returns:
            The values start·factor^i that do not exceed stop.
        """
        count = int(np.floor(np.log(self.stop / self.start) / np.log(self.factor) + 1e-9)) + 1
        return [self.start * self.factor**i for i in range(count)]


@dataclass(frozen=True, eq=False)
class Trial:
    """One experiment of a tuning procedure: gains, response, features and what was decided.

    Attributes:
        gains: the gains [K_p, K_i, K_d] tried (read-only copy), shape (3,).
        response: the step response they gave.
        features: the features of that response the procedure decided on.
        decision: what the procedure concluded from it, in words.
    """

    gains: np.ndarray
    response: Response
    features: StepFeatures
    decision: str

    def __post_init__(self) -> None:
        object.__setattr__(self, "gains", readonly(self.gains))


@dataclass(frozen=True, eq=False)
class ManualResult:
    """Chosen gains [K_p, K_i, K_d] (read-only copy) and every experiment that led to them.

    Attributes:
        gains: the chosen gains [K_p, K_i, K_d], shape (3,).
        trials: every experiment run, in order, with its decision.
        within_tolerance: False when no K_i on the ladder brought the steady-state error
            within the tolerance (the largest K_i tried is kept, and its trial says so).
    """

    gains: np.ndarray
    trials: list[Trial] = field(default_factory=list)
    within_tolerance: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "gains", readonly(self.gains))


class ManualSettings(StrictModel):
    """Ladders and tolerances of the procedure (units of the response: degrees in chapter 2).

    Attributes:
        kp: the rungs tried for K_p.
        ki: the rungs tried for K_i.
        kd: the rungs tried for K_d.
        band: the noise band about a level; swings inside it do not count.
        tolerance: the acceptable steady-state error.
    """

    kp: Ladder = Ladder(start=0.25, factor=1.5, stop=40.0)
    ki: Ladder = Ladder(start=0.1, factor=1.5, stop=40.0)
    kd: Ladder = Ladder(start=0.01, factor=2.0, stop=1.0)
    band: Positive = 2.0
    tolerance: Positive = 1.0


def manual_tuning(
    experiment: GainExperiment, settings: ManualSettings | None = None
) -> ManualResult:
    """Sect. 2.3.2.1 scripted: K_p to converging swings, K_i to zero error, K_d for overshoot.

    Every experiment is run once and kept with its decision. K_d is always tried at the first
    rung of its ladder (at least one experiment with K_d > 0), and raised only while the step
    response shows an overshoot lower by more than the noise band, no more swings and a
    steady-state error still within tolerance. Raises InfeasibleError if the smallest K_p
    already gives swings that grow or persist (the procedure has no K_p to keep).

    Args:
        experiment: runs one step response with gains [K_p, K_i, K_d].
        settings: ladders and tolerances; None for the defaults.

    Returns:
        The chosen gains and every experiment with its decision.
    """
    settings = settings or ManualSettings()
    trials: list[Trial] = []

    def run(gains: list[float]) -> StepFeatures:
        response = experiment(np.array(gains))
        features = step_features(response, settings.band)
        trials.append(Trial(np.array(gains), response, features, ""))
        return features

    def decide(index: int, text: str, replace: bool = False) -> None:
        old = trials[index]
        joined = f"{old.decision}; {text}" if old.decision and not replace else text
        trials[index] = Trial(old.gains, old.response, old.features, joined)

    # K_p with K_i = K_d = 0, up the ladder until the swings converge.
    kp, kept = 0.0, -1  # kept: index of the kept K_p's experiment
    for value in settings.kp.values():
        f = run([value, 0.0, 0.0])
        if f.oscillates and not f.converging:
            if kept < 0:
                decide(-1, "K_p: swings grow or persist at the smallest rung")
                raise InfeasibleError(
                    f"kp.start: the smallest K_p ({value:g}) already gives swings that grow or "
                    "persist; lower the K_p ladder's start"
                )
            decide(-1, "K_p: swings grow or persist; keep the previous K_p")
            break
        kp, kept = value, len(trials) - 1
        if f.converging:
            decide(-1, "K_p: converging oscillation reached")
            break
        decide(-1, "K_p: no oscillation yet; raise K_p")
    else:
        decide(kept, "K_p: top of the ladder without converging swings; keep it", replace=True)
    f = trials[kept].features  # the kept K_p's experiment: not run again
    # K_i until the steady-state error is within tolerance.
    ki, within = 0.0, True
    if f.steady_state_error > settings.tolerance:
        decide(kept, "K_i: steady-state error; raise K_i")
        within = False
        for value in settings.ki.values():
            ki = value
            f = run([kp, ki, 0.0])
            kept = len(trials) - 1
            if f.steady_state_error <= settings.tolerance:
                decide(-1, "K_i: steady-state error within tolerance")
                within = True
                break
            decide(-1, "K_i: steady-state error remains; raise K_i")
        else:
            decide(-1, "K_i: top of the ladder with the error above tolerance; keep this K_i")
    else:
        decide(kept, "K_i: no steady-state error; K_i = 0")
    # K_d: at least one rung, kept only while the step response improves.
    kd, best = 0.0, f
    for value in settings.kd.values():
        g = run([kp, ki, value])
        better = (
            g.overshoot < best.overshoot - settings.band
            and g.peak_sizes.size <= best.peak_sizes.size
            and g.steady_state_error <= max(settings.tolerance, best.steady_state_error)
        )
        if not better:
            decide(
                -1,
                f"K_d: overshoot not lower by more than the band ({g.overshoot:.3g} vs "
                f"{best.overshoot:.3g}), or more swings ({g.peak_sizes.size} vs "
                f"{best.peak_sizes.size}), or more error; keep K_d = {kd:g}",
            )
            break
        decide(-1, "K_d: less overshoot; raise K_d")
        kd, best = value, g
    return ManualResult(np.array([kp, ki, kd]), trials, within)


ZnRule = Literal["P", "PI", "PID"]
# Classic Ziegler-Nichols ultimate-gain table: (K_p/K_u, T_i/T_u, T_d/T_u).
ZIEGLER_NICHOLS: dict[str, tuple[float, float, float]] = {
    "P": (0.5, np.inf, 0.0),
    "PI": (0.45, 1 / 1.2, 0.0),
    "PID": (0.6, 0.5, 0.125),
}


def ziegler_nichols(ku: float, tu: float, rule: ZnRule = "PID") -> np.ndarray:
    """[K_p, K_i, K_d] from ultimate gain K_u and period T_u: K_i = K_p/T_i, K_d = K_p T_d.

    Args:
        ku: ultimate gain K_u, the P-only gain of sustained oscillation.
        tu: ultimate period T_u of that oscillation [s].
        rule: row of the classic Ziegler-Nichols table: "P", "PI" or "PID".

    Returns:
        The gains [K_p, K_i, K_d], shape (3,) (K_i per second, K_d times seconds).
    """
    if rule not in ZIEGLER_NICHOLS:
        raise ConfigError("rule", f"unknown rule {rule!r}; use one of {sorted(ZIEGLER_NICHOLS)}")
    if not (ku > 0 and tu > 0 and np.isfinite(ku) and np.isfinite(tu)):
        raise ConfigError("ku", f"K_u and T_u must be finite and positive (got {ku}, {tu})")
    a, b, c = ZIEGLER_NICHOLS[rule]
    kp = a * ku
    return np.array([kp, kp / (b * tu), kp * c * tu])


def ultimate_gain(
    experiment: GainExperiment, ladder: Ladder, band: float, sustained: float = 0.8
) -> tuple[float, float, list[Trial]]:
    """(K_u, T_u, experiments): the first P-only gain whose swings keep `sustained` of size.

    Raises InfeasibleError if no gain on the ladder gives a sustained oscillation.

    Args:
        experiment: runs one step response with gains [K_p, K_i, K_d].
        ladder: the K_p values tried in turn (K_i = K_d = 0).
        band: noise band about a level; swings inside it do not count (response units).
        sustained: fraction of the first swings' size the last swings must keep.

    Returns:
        The ultimate gain K_u, the ultimate period T_u [s], and every experiment run.
    """
    trials: list[Trial] = []
    for kp in ladder.values():
        gains = np.array([kp, 0.0, 0.0])
        response = experiment(gains)
        f = step_features(response, band)
        hit = f.sustained(sustained)
        trials.append(Trial(gains, response, f, "sustained" if hit else "decays or none"))
        if hit:
            return kp, f.period, trials
    raise InfeasibleError(
        f"no sustained oscillation up to K_p = {ladder.stop:g}; raise the ladder's stop"
    )
