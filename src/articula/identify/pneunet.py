"""The PneuNet's constants from recordings of its valve's PWM count and the flex sensor's
angle: the actuator model (plants.pneunet: valve, chamber, saturating pressure-to-angle map,
second-order bending) driven by the recorded count, its angle against the measured one.

Without a pressure sensor only the ratio of the supply pressure to the map's pressure scale
shows in the angle, and the valve's lag and the chamber's, in series, trade places: the supply
pressure (a pump's rating) and the valve's time constant (its datasheet's) are taken as given
(the start's) and never fitted; pressure_scale and chamber_tau are fitted relative to them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from articula.identify.fit import (
    VALIDATION,
    Curve,
    Fit,
    Identification,
    fit_recordings,
    sample_period,
)
from articula.plants.pneunet import PneuNetBatch, PneuNetParams

CONSTANTS = (
    "chamber_tau",
    "natural_frequency",
    "damping_ratio",
    "pressure_scale",
    "theta_max",
)
# What the angle alone cannot tell apart: the supply pressure from the map's pressure scale
# (only their ratio shows), and the valve's lag from the chamber's (two lags in series: fitted
# both, half of ten hidden actuators came out with the two swapped, at a lower cost).
GIVEN = ("supply_pressure", "valve_tau")
PWM_FULL = 255.0  # the valve's PWM count at full duty
SAMPLES_PER_CYCLE = 4  # the fewest samples a cycle that resolve a mode's frequency and decay
_DEFAULTS = PneuNetParams().model_dump()  # every constant a trial point does not set


@dataclass(frozen=True)
class PneuNetRecording:
    """One PneuNet recording, as the fit takes it.

    Attributes:
        dt: the PWM period [s].
        pwm: the valve's PWM count over each period, shape (n,).
        angle: the measured angle at each period's start [deg], shape (n,).
    """

    dt: float
    pwm: np.ndarray
    angle: np.ndarray

    @classmethod
    def from_columns(cls, columns: Mapping[str, np.ndarray], where: str) -> PneuNetRecording:
        """A recording's trace columns checked for the fit.

        Args:
            columns: column name -> values: t [s], pwm [counts], angle [deg].
            where: the recording, named in errors.

        Returns:
            The recording.
        """
        dt = sample_period(columns, ("pwm", "angle"), 30, where, "PneuNet")
        pwm, angle = (np.asarray(columns[c], dtype=float) for c in ("pwm", "angle"))
        return cls(dt, pwm, angle)


def simulate(constants: Mapping[str, float], recording: PneuNetRecording) -> np.ndarray:
    """The actuator with `constants` driven by the recording's PWM counts, from rest.

    Args:
        constants: PneuNetParams' constants by name (SI); the rest at their defaults.
        recording: the recording whose counts drive it.

    Returns:
        The bending angle at each period's start [deg], shape (n,).
    """
    # Built without validation: a trial point of the fit may bend less than the book's 90°.
    params = PneuNetParams.model_construct(
        **(_DEFAULTS | dict(constants) | {"pwm_period": recording.dt})
    )
    plant = PneuNetBatch(params, 1)
    angle = np.empty(recording.pwm.size)
    for k, count in enumerate(recording.pwm):
        angle[k] = plant.theta[0]
        plant.advance(np.array([count / PWM_FULL]))
    return np.degrees(np.clip(angle, *sensor_range(params)))


def sensor_range(params: PneuNetParams) -> tuple[float, float]:
    """The angles the flex sensor's ADC can read, beyond which it reads its end [rad] (the
    book's sensor reads up to 144°; a hidden actuator that bends further showed the clip).

    Args:
        params: the sensor's zero, gain and ADC reference.

    Returns:
        The lowest and highest readable angle [rad].
    """
    if params.adc_bits == 0:
        return -np.inf, np.inf
    low = -params.sensor_zero / params.sensor_gain
    return low, (params.adc_vref - params.sensor_zero) / params.sensor_gain


def identify_pneunet(
    recordings: Sequence[PneuNetRecording], start: PneuNetParams | None = None
) -> Identification:
    """Fit the PneuNet's constants to the first three quarters of each recording; validate on
    the rest.

    Args:
        recordings: recordings from rest (open-loop PWM steps, or a closed loop's).
        start: where the fit starts, and the supply pressure it takes as given; None: the
            defaults.

    Returns:
        The identification; its plant, a pneunet.pid config's [plant] table.
    """
    start = start or PneuNetParams()

    def predict(constants: dict[str, float], k: int) -> dict[str, np.ndarray]:
        """The model's angle for recording k."""
        return {"angle": simulate(constants, recordings[k])}

    begin = {name: getattr(start, name) for name in (*CONSTANTS, *GIVEN)}
    begin |= _static_estimate(recordings, begin)
    measured = [{"angle": r.angle} for r in recordings]
    fit, validation, begin = fit_recordings(predict, measured, begin, CONSTANTS)
    # The given constants are not found: named with the undetermined ones.
    fit = dataclasses.replace(fit, unidentifiable=(*fit.unidentifiable, *GIVEN))
    constants = begin | fit.values
    plant = {
        "experiment": "pneunet.pid",
        "plant": start.model_dump() | constants | {"trial_spread": 0.0},
    }
    first = recordings[0]
    t = np.arange(first.pwm.size) * first.dt
    cut = t[int(t.size * (1 - VALIDATION))]
    curves = (Curve("angle [deg]", t, first.angle, simulate(constants, first), cut),)
    fit, bounds = _beyond_sampling(fit, first.dt)
    return Identification(fit, validation, begin, plant, curves, bounds)


def _beyond_sampling(fit: Fit, dt: float) -> tuple[Fit, dict[str, str]]:
    """The bending mode declared unidentifiable where it is faster than the sampling resolves:
    a damped oscillation needs SAMPLES_PER_CYCLE samples a cycle to show its frequency and
    decay, so ω ≤ 2π / (SAMPLES_PER_CYCLE · dt). Beyond it the fit still finds a mode that
    reproduces the samples (the plant keeps it), but its frequency and damping are no
    measurement: a PneuNet bending at 80-150 rad/s, sampled at 30 Hz, came out 20-60 % slow
    with its damping 55 % high and standard errors of a few percent."""
    fastest = 2 * np.pi / (SAMPLES_PER_CYCLE * dt)
    if fit.values.get("natural_frequency", 0.0) <= fastest:
        return fit, {}
    why = (f"≥ {fastest:.1f} rad/s: faster than {SAMPLES_PER_CYCLE} samples of {1e3 * dt:.1f} ms "
           "a cycle resolve; sample faster to measure it")  # fmt: skip
    bounds = {"natural_frequency": why, "damping_ratio": f"of a mode {why}"}
    kept = {k: v for k, v in fit.values.items() if k not in bounds}
    errors = {k: v for k, v in fit.standard_errors.items() if k not in bounds}
    unidentifiable = (*fit.unidentifiable, *bounds)
    return dataclasses.replace(fit, values=kept, standard_errors=errors,
                               unidentifiable=unidentifiable), bounds  # fmt: skip


def _static_estimate(
    recordings: Sequence[PneuNetRecording], start: dict[str, float]
) -> dict[str, float]:
    """theta_max and pressure_scale from the angles the steps settle at (the last quarter of
    each recording held at one count): θ = θ_max (1 − exp(−P_s d / p_c)) at duty d, solved by
    least squares (the dynamic fit, started far from it, settled in a minimum with the map
    40-60 % off in three of ten hidden actuators). Empty with fewer than two held counts."""
    duty, settled = [], []
    top = sensor_range(PneuNetParams.model_construct(**(_DEFAULTS | start)))[1]
    for r in recordings:
        angle = np.radians(np.mean(r.angle[-max(r.angle.size // 4, 1) :]))
        if np.ptp(r.pwm) == 0 and r.pwm[0] > 0 and angle < 0.98 * top:  # not at the clip
            duty.append(r.pwm[0] / PWM_FULL)
            settled.append(angle)
    if len(set(duty)) < 2:
        return {}
    duty_, settled_ = np.array(duty), np.array(settled)
    supply = start["supply_pressure"]

    def error(x: np.ndarray) -> np.ndarray:
        """The map's angles at the held duties, less the settled ones [rad]."""
        theta_max, scale = np.exp(x)
        return theta_max * -np.expm1(-supply * duty_ / scale) - settled_

    x0 = np.log([start["theta_max"], start["pressure_scale"]])
    theta_max, scale = np.exp(least_squares(error, x0).x)
    return {"theta_max": float(theta_max), "pressure_scale": float(scale)}
