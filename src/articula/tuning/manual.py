"""Manual tuning of Sect. 2.3.2.1 as a scripted procedure, and the Ziegler-Nichols table.

The procedure decides from each step response only, as an operator watching the rig would:
raise K_p (K_i = K_d = 0) until the response oscillates and the swings die out; then raise
K_i until the steady-state error is within tolerance; then raise K_d while it lowers the
overshoot without adding swings. Every experiment is kept, for Fig. 2.5.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from articula.errors import ConfigError, InfeasibleError
from articula.tuning.response import Experiment, Response, StepFeatures, step_features


@dataclass(frozen=True)
class Ladder:
    """Values tried in turn: start, start·factor, ... up to at most `stop`."""

    start: float
    factor: float
    stop: float

    def __post_init__(self) -> None:
        if not (0 < self.start <= self.stop and self.factor > 1):
            raise ConfigError("ladder", f"need 0 < start <= stop and factor > 1 (got {self})")

    def values(self) -> list[float]:
        """The rungs, smallest first."""
        count = int(np.floor(np.log(self.stop / self.start) / np.log(self.factor) + 1e-9)) + 1
        return [self.start * self.factor**i for i in range(count)]


@dataclass(frozen=True)
class Trial:
    """One experiment of a tuning procedure: gains, response, features and what was decided."""

    gains: np.ndarray
    response: Response
    features: StepFeatures
    decision: str


@dataclass(frozen=True)
class ManualResult:
    """Chosen gains [K_p, K_i, K_d] and every experiment that led to them."""

    gains: np.ndarray
    trials: list[Trial] = field(default_factory=list)


@dataclass(frozen=True)
class ManualSettings:
    """Ladders and tolerances of the procedure (units of the response: degrees in chapter 2)."""

    kp: Ladder = Ladder(0.25, 1.5, 40.0)
    ki: Ladder = Ladder(0.1, 1.5, 40.0)
    kd: Ladder = Ladder(0.01, 2.0, 1.0)
    band: float = 2.0  # noise band about a level
    tolerance: float = 1.0  # acceptable steady-state error


def manual_tuning(
    experiment: Experiment, settings: ManualSettings = ManualSettings()
) -> ManualResult:
    """Sect. 2.3.2.1 scripted: K_p to converging swings, K_i to zero error, K_d for overshoot."""
    trials: list[Trial] = []

    def run(gains: list[float]) -> StepFeatures:
        response = experiment(np.array(gains))
        features = step_features(response, settings.band)
        trials.append(Trial(np.array(gains), response, features, ""))
        return features

    def decide(text: str) -> None:
        last = trials[-1]
        trials[-1] = Trial(last.gains, last.response, last.features, text)

    kp = settings.kp.start
    for value in settings.kp.values():
        f = run([value, 0.0, 0.0])
        if f.oscillates and not f.converging:
            decide("K_p: swings grow or persist; keep the previous K_p")
            break
        kp = value
        if f.converging:
            decide("K_p: converging oscillation reached")
            break
        decide("K_p: no oscillation yet; raise K_p")
    ki = 0.0
    f = run([kp, 0.0, 0.0])
    if f.steady_state_error > settings.tolerance:
        decide("K_i: steady-state error; raise K_i")
        for value in settings.ki.values():
            ki = value
            f = run([kp, ki, 0.0])
            if f.steady_state_error <= settings.tolerance:
                decide("K_i: steady-state error within tolerance")
                break
            decide("K_i: steady-state error remains; raise K_i")
    else:
        decide("K_i: no steady-state error; K_i = 0")
    kd, best = 0.0, f
    if best.overshoot <= settings.band:
        decide(trials[-1].decision + "; no overshoot beyond the noise band, so K_d = 0")
        return ManualResult(np.array([kp, ki, kd]), trials)
    for value in settings.kd.values():
        g = run([kp, ki, value])
        better = (
            g.overshoot < best.overshoot - settings.band
            and g.peak_sizes.size <= best.peak_sizes.size
            and g.steady_state_error <= max(settings.tolerance, best.steady_state_error)
        )
        if not better:
            decide("K_d: more swings or no less overshoot; keep the previous K_d")
            break
        decide("K_d: less overshoot; raise K_d")
        kd, best = value, g
    return ManualResult(np.array([kp, ki, kd]), trials)


ZnRule = Literal["P", "PI", "PID"]
# Classic Ziegler-Nichols ultimate-gain table: (K_p/K_u, T_i/T_u, T_d/T_u).
ZIEGLER_NICHOLS: dict[str, tuple[float, float, float]] = {
    "P": (0.5, np.inf, 0.0),
    "PI": (0.45, 1 / 1.2, 0.0),
    "PID": (0.6, 0.5, 0.125),
}


def ziegler_nichols(ku: float, tu: float, rule: ZnRule = "PID") -> np.ndarray:
    """[K_p, K_i, K_d] from ultimate gain K_u and period T_u [s]: K_i = K_p/T_i, K_d = K_p T_d."""
    if rule not in ZIEGLER_NICHOLS:
        raise ConfigError("rule", f"unknown rule {rule!r}; use one of {sorted(ZIEGLER_NICHOLS)}")
    if not (ku > 0 and tu > 0 and np.isfinite(ku) and np.isfinite(tu)):
        raise ConfigError("ku", f"K_u and T_u must be finite and positive (got {ku}, {tu})")
    a, b, c = ZIEGLER_NICHOLS[rule]
    kp = a * ku
    return np.array([kp, kp / (b * tu), kp * c * tu])


def ultimate_gain(
    experiment: Experiment, ladder: Ladder, band: float, sustained: float = 0.8
) -> tuple[float, float, list[Trial]]:
    """(K_u, T_u, experiments): the first P-only gain whose swings keep `sustained` of size."""
    trials: list[Trial] = []
    for kp in ladder.values():
        gains = np.array([kp, 0.0, 0.0])
        response = experiment(gains)
        f = step_features(response, band)
        hit = f.peak_sizes.size >= 3 and f.decay >= sustained
        trials.append(Trial(gains, response, f, "sustained" if hit else "decays or none"))
        if hit:
            return kp, f.period, trials
    raise InfeasibleError(
        f"no sustained oscillation up to K_p = {ladder.stop:g}; raise the ladder's stop"
    )
