"""Chapter 3's single simulations beside the sweeps: the model, its sensitivity, the mechanism.

Every run here uses the ideal sensor and reports the true angle.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from articula.book.ch3.calibration import undamped
from articula.control.damping import DampingPolicy
from articula.experiments.six_chamber import DeactuationConfig, run_metrics, simulate_deactuation
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import SixChamberParams, gas_stiffness, natural_frequency
from articula.plants.six_chamber_sim import ValveSchedule, fill_time, integrate

IDEAL = OrientationSensorParams(ideal=True)
BOOK_PULSE = DampingPolicy(delta=0.5)  # Sect. 3.4: at the vent command, vented once filled
HELD_PULSE = DampingPolicy(delta=0.5, length=0.1)  # the same pulse held 0.1 s
ORIFICES = (0.5e-3, 1.0e-3, 2.0e-3, 3.0e-3)  # sensitivity: valve orifice diameter [m]
TRANSITIONS = (50.0, 500.0, 5000.0)  # sensitivity: orifice flow_transition [Pa]
STIFFENING = (0.0, 0.5, 1.0)  # what-if: V E k² rises by this much per full chamber
MECHANISM_MAX_DELTA = 0.35  # the mechanism is shown at the best δ in (0, this]
VENTED = 0.05  # chamber 0 counts as vented below this fraction of supply
FREE_SWING_S = 2.0  # [s] simulated after releasing the bend with every chamber vented


@dataclass(frozen=True)
class Outcome:
    """True-angle result of one deactuation: peak past rest [deg], settling [s] (NaN: never),
    bend before venting [deg]."""

    peak_deg: float
    settling_s: float
    bend_deg: float


@dataclass(frozen=True)
class ActuatorModel:
    """The calibrated model's derived constants and its undamped deactuation.

    Attributes:
        params: the actuator's constants.
        natural_frequency: ω_n of the body alone [rad/s].
        damping_ratio: ζ of the body alone.
        fill_half_s, fill_90_s: valve open time to 50 % and 90 % of supply [s].
        gas_stiffness_atm, gas_stiffness_half: six sealed chambers' stiffness [N·m/rad] at
            atmospheric pressure and at half the supply.
        undamped: the undamped deactuation (δ = 0).
    """

    params: SixChamberParams
    natural_frequency: float
    damping_ratio: float
    fill_half_s: float
    fill_90_s: float
    gas_stiffness_atm: float
    gas_stiffness_half: float
    undamped: Outcome


@dataclass(frozen=True)
class ValveCase:
    """One changed valve constant: its label, the undamped run and the book's pulse."""

    label: str
    free: Outcome
    pulse: Outcome


@dataclass(frozen=True)
class Release:
    """Chamber 0 and the body after the vent command, until the body first reaches rest.

    Attributes:
        peak_deg: peak past rest [deg].
        rest_s: time to first reach rest [s].
        p0_mean: chamber 0's mean gauge pressure until then [Pa].
        vented_s: time for chamber 0 to fall below VENTED of supply [s].
        overshoot: largest swing past rest over the bend at the vent command.
        beta0: bending vector at the vent command [rad].
        direction: unit vector of the bend.
    """

    peak_deg: float
    rest_s: float
    p0_mean: float
    vented_s: float
    overshoot: float
    beta0: tuple[float, float]
    direction: np.ndarray


@dataclass(frozen=True)
class Mechanism:
    """The book's pulse at `delta` against none, and the bend released with chambers vented."""

    delta: float
    free: Release
    pulsed: Release
    vented_overshoot: float


@dataclass(frozen=True)
class StiffeningRow:
    """Outcomes with no pulse, the book's pulse and the held pulse for one stiffening s."""

    stiffening: float
    outcomes: tuple[Outcome, Outcome, Outcome]


def outcome(
    policy: DampingPolicy | None = None,
    actuator: SixChamberParams | None = None,
    side_deg: float = 0.0,
) -> Outcome:
    """The true-angle outcome of one deactuation of side `side_deg` [deg] with the ideal sensor
    (default: no pulse, the calibrated actuator)."""
    config = DeactuationConfig(
        side_deg=side_deg,
        actuator=actuator or SixChamberParams(),
        damping=policy or DampingPolicy(),
        sensor=IDEAL,
    )
    return _outcome(run_metrics(simulate_deactuation(config), config.band_deg))


def _outcome(m: dict[str, float]) -> Outcome:
    """An Outcome from run_metrics' true-angle entries."""
    return Outcome(m["peak_true_deg"], m["settling_true_s"], m["deactuation_angle_deg"])


def actuator_model(p: SixChamberParams | None = None) -> ActuatorModel:
    """The constants derived from `p` (default: the calibrated actuator) and its undamped
    deactuation."""
    p = p or SixChamberParams()
    wn, zeta = natural_frequency(p)
    return ActuatorModel(
        p,
        wn,
        zeta,
        fill_time(p, 0.5 * p.supply),
        fill_time(p, 0.9 * p.supply),
        gas_stiffness(p, p.atmosphere),
        gas_stiffness(p, p.atmosphere + 0.5 * p.supply),
        _outcome(undamped(p)),
    )


def sensitivity() -> tuple[ValveCase, ...]:
    """The undamped run and the book's pulse with one assumed valve constant changed."""
    cases = [("orifice_diameter", d, f"orifice {d * 1e3:g} mm") for d in ORIFICES]
    cases += [("flow_transition", f, f"flow_transition {f:g} Pa") for f in TRANSITIONS]
    return tuple(
        ValveCase(label, outcome(actuator=a), outcome(BOOK_PULSE, a))
        for name, value, label in cases
        for a in [SixChamberParams(**{name: value})]
    )


def mechanism_delta(delta: Sequence[float], peak_deg: Sequence[float | None]) -> float:
    """The δ in (0, MECHANISM_MAX_DELTA] with the lowest sensor peak (else the largest δ)."""
    peak = [np.inf if x is None else x for x in peak_deg]
    small = [d for d in delta if 0 < d <= MECHANISM_MAX_DELTA]
    return min(small, key=lambda d: peak[list(delta).index(d)]) if small else delta[-1]


def release(delta: float) -> Release:
    """The book's pulse at δ: the body and chamber 0 from the vent command to first rest."""
    p = SixChamberParams()
    config = DeactuationConfig(sensor=IDEAL, damping=DampingPolicy(delta=delta))
    run = simulate_deactuation(config)
    after = run.sim.t >= config.hold
    t, angle = run.sim.t[after] - config.hold, run.sim.beta[after] @ run.direction
    p0 = run.sim.gauge[after, 0]
    rest = int(np.nonzero(angle <= 0)[0][0])
    return Release(
        peak_deg=run_metrics(run, config.band_deg)["peak_true_deg"],
        rest_s=float(t[rest]),
        p0_mean=float(p0[:rest].mean()),
        vented_s=float(t[np.nonzero(p0 < VENTED * p.supply)[0][0]]),
        overshoot=float(-angle.min() / angle[0]),
        beta0=tuple(run.sim.beta[after][0]),
        direction=run.direction,
    )


def vented_overshoot(beta0: tuple[float, float], direction: np.ndarray) -> float:
    """Overshoot of the body released at β0 [rad] with every chamber already at atmosphere."""
    sim = integrate(SixChamberParams(), ValveSchedule.build([]), FREE_SWING_S, beta0=beta0)
    angle = sim.beta @ direction
    return float(-angle.min() / angle[0])


def mechanism(delta: Sequence[float], peak_deg: Sequence[float | None]) -> Mechanism:
    """No pulse against the book's pulse at the best small δ of the sweep (`mechanism_delta`)."""
    best = mechanism_delta(delta, peak_deg)
    free = release(0.0)
    return Mechanism(best, free, release(best), vented_overshoot(free.beta0, free.direction))


def stiffening() -> tuple[StiffeningRow, ...]:
    """No pulse, the book's pulse and the held pulse for a body stiffening with pressure."""
    rows = []
    for s in STIFFENING:
        a = SixChamberParams(stiffening=s)
        rows.append(
            StiffeningRow(s, (outcome(actuator=a), outcome(BOOK_PULSE, a), outcome(HELD_PULSE, a)))
        )
    return tuple(rows)
