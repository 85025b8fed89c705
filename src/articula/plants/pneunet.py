"""Simulated PneuNet bending actuator of chapter 2: PWM valve, chamber, bending, flex sensor.

Chain (one PWM period T at a time, vectorised over a batch of trials):
duty → solenoid valve (on for duty·T, off for the rest; the valve's opening lags its command
by τ_v) → chamber pressure, a first-order lag τ_p towards supply·opening (so the mean
pressure is proportional to duty, Sect. 2.4.1.2) → optional play (hysteresis) → saturating
pressure-to-angle map → lightly damped second-order bending (exact over a period for the
period's mean pressure) → flex sensor on a 10-bit ADC.
The book gives the valve period only; every other number is chosen and explained below and
in docs/deviations.md (Chapter 2).
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from pydantic import Field, model_validator
from scipy.linalg import expm

from articula.errors import ConfigError
from articula.validation import NonNegative, Positive, StrictModel, field_error


class PneuNetParams(StrictModel):
    """Constants of the simulated PneuNet in SI units, with the source or reason of each.

    Attributes:
        pwm_period: valve switching period T [s] (1/30 s, Sect. 2.4.1.2).
        valve_tau: time constant τ_v of the valve's opening [s] (3τ_v = 0.2 s).
        supply_pressure: pump pressure P_s, gauge [Pa].
        chamber_tau: fill/vent time constant τ_p of the chamber [s] (calibrated).
        theta_max: asymptote θ_max of the saturating pressure-to-angle map [rad].
        pressure_scale: pressure scale p_c of that map, θ_eq = θ_max (1 − exp(−p/p_c)) [Pa].
        natural_frequency: natural frequency ω_n of the bending [rad/s].
        damping_ratio: damping ratio ζ of the bending, in (0, 1).
        hysteresis: width of the play operator on the pressure [Pa]; 0: none.
        sensor_zero: flex-sensor output at 0° [V].
        sensor_gain: flex-sensor output per radian [V/rad].
        sensor_noise: standard deviation of the flex sensor's angle noise [rad].
        adc_bits: ADC resolution [bits]; 0: no quantisation.
        adc_vref: ADC reference voltage [V].
        trial_spread: relative standard deviation of the per-trial scales of supply pressure,
            chamber τ and bending reach (clipped to [0.5, 1.5]).
    """

    # Valve switching period, Sect. 2.4.1.2: T = 1/30 s.
    pwm_period: Positive = 1.0 / 30.0
    # Cheap solenoid valves need ~0.2 s to open or close fully: 3τ_v = 0.2 s.
    valve_tau: Positive = 0.2 / 3.0
    # Supply pressure: PneuNets of Dragon Skin 10 are driven at a few tens of kPa.
    supply_pressure: Positive = 50e3
    # Chamber fill/vent time constant through the valve orifice; sets, with the valve lag, the
    # bandwidth (tracks 0.5 Hz, not 5 Hz, Sect. 2.4.2.2); calibrated, not measured.
    chamber_tau: Positive = 0.25
    # Saturating map θ_eq = θ_max (1 − exp(−p/p_c)): 90° at ~78 % of supply, ~100° at full.
    theta_max: Positive = math.radians(120.0)
    pressure_scale: Positive = 27.9e3
    # Bending: a free PneuNet finger swings at a few Hz and its silicone damps it little.
    natural_frequency: Positive = 2 * math.pi * 3.0
    damping_ratio: Annotated[float, Field(gt=0, lt=1, allow_inf_nan=False)] = 0.15
    # Optional hysteresis: width of a play operator on the pressure (0: none).
    hysteresis: NonNegative = 0.0
    # Flex sensor mapped linearly to volts (the book fits resistance to angle from data).
    sensor_zero: NonNegative = 1.0
    sensor_gain: Positive = 2.5 / (math.pi / 2)
    # Flex-sensor dividers on an Arduino ADC wander by a couple of counts: σ ≈ 2 LSB ≈ 0.35°.
    sensor_noise: NonNegative = math.radians(0.35)
    adc_bits: Annotated[int, Field(ge=0, le=24)] = 10
    adc_vref: Positive = 5.0
    # Structural uncertainty between trials (the chapter's subject): the pump's pressure, the
    # chamber's fill time and the bending reach of each trial are scaled by 1 + spread·N(0, 1),
    # clipped to [0.5, 1.5]. Chosen as a plausible rig-to-rig drift, not fitted to the book.
    trial_spread: Annotated[float, Field(ge=0, le=0.2, allow_inf_nan=False)] = 0.05

    @model_validator(mode="after")
    def _check(self) -> PneuNetParams:
        reach = self.theta_max * (1 - math.exp(-self.supply_pressure / self.pressure_scale))
        if reach <= math.radians(90.0):
            raise field_error(
                "supply_pressure",
                f"full supply ({self.supply_pressure:g} Pa) bends only "
                f"{math.degrees(reach):.1f}°; the book's range is 0-90°, so raise "
                "supply_pressure or theta_max",
            )
        return self

    def equilibrium_angle(
        self, pressure: np.ndarray, reach: np.ndarray | float = 1.0
    ) -> np.ndarray:
        """Static bending angle [rad] at chamber pressure [Pa] (saturating map), × reach.

        Args:
            pressure: chamber gauge pressure, any shape [Pa]; negative counts as 0.
            reach: scale of the bending reach (a trial factor), broadcast with `pressure`.

        Returns:
            The equilibrium angle θ_eq, shaped as `pressure` [rad].
        """
        theta = self.theta_max * -np.expm1(-np.maximum(pressure, 0.0) / self.pressure_scale)
        return reach * theta

    def trial_factors(self, rng: np.random.Generator) -> np.ndarray:
        """Scales of [supply pressure, chamber τ, bending reach] for one trial.

        Args:
            rng: random generator of the trial's draw.

        Returns:
            The three scales, shape (3,), each 1 + trial_spread·N(0, 1) clipped to [0.5, 1.5].
        """
        return np.clip(1.0 + self.trial_spread * rng.standard_normal(3), 0.5, 1.5)


class PneuNetBatch:
    """State of `trials` actuators at rest, advanced one PWM period at a time.

    Args:
        params: the actuator's constants.
        trials: number of actuators simulated side by side (>= 1).
        factors: scales of supply pressure, chamber τ and bending reach per trial, shape
            (trials, 3) (PneuNetParams.trial_factors); None: the nominal actuator for all.

    Attributes:
        supply: supply pressure of each trial, shape (trials,) [Pa].
        chamber_tau: chamber time constant of each trial, shape (trials,) [s].
        reach: bending-reach scale of each trial, shape (trials,).
        valve: valve opening, shape (trials,), in [0, 1].
        pressure: chamber gauge pressure, shape (trials,) [Pa].
        played: pressure after the play operator, shape (trials,) [Pa].
        theta: bending angle, shape (trials,) [rad].
        omega: bending rate, shape (trials,) [rad/s].
    """

    def __init__(
        self, params: PneuNetParams, trials: int, factors: np.ndarray | None = None
    ) -> None:
        if isinstance(trials, bool) or not isinstance(trials, int | np.integer) or trials < 1:
            raise ConfigError("trials", f"must be an integer >= 1 (got {trials!r})")
        self.params = params
        f = np.ones((trials, 3)) if factors is None else np.asarray(factors, dtype=float)
        if f.shape != (trials, 3) or not np.all(np.isfinite(f)) or np.any(f <= 0):
            raise ConfigError(
                "factors",
                f"need finite positive scales of shape ({trials}, 3) = (trials, [supply, "
                f"chamber τ, reach]) (got shape {f.shape})",
            )
        self.supply = params.supply_pressure * f[:, 0]
        self.chamber_tau = params.chamber_tau * f[:, 1]
        self.reach = f[:, 2]
        wn, zeta = params.natural_frequency, params.damping_ratio
        A = np.array([[0.0, 1.0], [-(wn**2), -2 * zeta * wn]])
        self._bending = expm(A * params.pwm_period)  # transition of [θ − θ_eq, θ'] over T
        self.valve = np.zeros(trials)  # opening in [0, 1]
        self.pressure = np.zeros(trials)  # [Pa]
        self.played = np.zeros(trials)  # [Pa] pressure after the play operator
        self.theta = np.zeros(trials)  # [rad]
        self.omega = np.zeros(trials)  # [rad/s]

    def advance(self, duty: np.ndarray) -> None:
        """Apply `duty` in [0, 1] (one per trial) for one PWM period.

        Args:
            duty: valve duty cycle of each trial, shape (trials,); clipped to [0, 1].
        """
        p = self.params
        d = np.minimum(np.maximum(duty, 0.0), 1.0)
        T = p.pwm_period
        # Valve and chamber are linear between switchings: advance both exactly through the
        # on-phase (command 1) and the off-phase (command 0) of the period.
        start = self.pressure
        self._linear_segment(1.0, d * T)
        self._linear_segment(0.0, (1.0 - d) * T)
        # The bending sees the pressure's mean over the period (trapezoid of its ends).
        mean_p = 0.5 * (start + self.pressure)
        if p.hysteresis > 0:
            half = 0.5 * p.hysteresis
            self.played = np.clip(self.played, mean_p - half, mean_p + half)
            mean_p = self.played
        target = p.equilibrium_angle(mean_p, self.reach)
        # θ'' = ω_n²(θ_eq − θ) − 2ζω_n θ' is linear for a held θ_eq: exact over the period.
        (a, b), (c, d) = self._bending
        offset = self.theta - target
        self.theta = target + a * offset + b * self.omega
        self.omega = c * offset + d * self.omega

    def _linear_segment(self, command: float, duration: np.ndarray) -> None:
        """Exact solution of τ_v x' = u − x, τ_p p' = P_s x − p over `duration` [s].

        p(t) − P_s u = (p0 − P_s u) e_p + P_s x0 · τ_v/(τ_v − τ_p) · (e_v − e_p), with
        e_v = exp(−t/τ_v), e_p = exp(−t/τ_p). The last term is written as
        P_s x0 · (t/τ_p) · e_slow · φ(s), e_slow the slower of e_v and e_p,
        s = −|1/τ_p − 1/τ_v|·t ≤ 0 and φ(s) = expm1(s)/s (φ(0) = 1): the same number
        without the division by τ_v − τ_p, so τ_v = τ_p (the repeated pole, whose term is
        P_s x0 (t/τ_p) e_p) and τ_v close to τ_p are exact too.
        """
        p = self.params
        tv, tp, ps = p.valve_tau, self.chamber_tau, self.supply
        t = duration
        ev = np.exp(-t / tv)
        ep = np.exp(-t / tp)
        x0 = self.valve - command
        slow = np.exp(-t / np.maximum(tv, tp))
        s = -np.abs(1.0 / tp - 1.0 / tv) * t
        phi = np.ones_like(s)
        np.divide(np.expm1(s), s, out=phi, where=s != 0)
        self.pressure = (
            ps * command + (self.pressure - ps * command) * ep + ps * x0 * (t / tp) * slow * phi
        )
        self.valve = command + x0 * ev

    def read_code(self, noise: np.ndarray) -> np.ndarray:
        """The flex sensor's ADC code (adc_bits > 0): the divider's volts with noise, floored.

        Args:
            noise: standard normal draws, one per trial, shape (trials,).

        Returns:
            The codes, shape (trials,), in [0, 2^adc_bits − 1] (as floats).
        """
        p = self.params
        volts = p.sensor_zero + p.sensor_gain * (self.theta + p.sensor_noise * noise)
        lsb = p.adc_vref / 2**p.adc_bits
        return np.minimum(np.maximum(np.floor(volts / lsb), 0), 2**p.adc_bits - 1)

    def read(self, noise: np.ndarray) -> np.ndarray:
        """Flex-sensor angle [rad] as the controller reads it: noise, the ADC, back to angle.

        Args:
            noise: standard normal draws, one per trial, shape (trials,).

        Returns:
            The measured bending angle of each trial, shape (trials,) [rad].
        """
        p = self.params
        if p.adc_bits:
            volts = (self.read_code(noise) + 0.5) * (p.adc_vref / 2**p.adc_bits)  # mid-step
        else:
            volts = p.sensor_zero + p.sensor_gain * (self.theta + p.sensor_noise * noise)
        return (volts - p.sensor_zero) / p.sensor_gain
