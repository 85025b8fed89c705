"""Discrete PID of chapter 2, Eqs. (2.2)-(2.4), with gains scheduled on the reference.

One controller serves the ordinary PID (constant gains), the piecewise PID (gains constant on
each subrange of θ_r) and the "fuzzy" PID (gains piecewise-linear in θ_r between the
representative points, Fig. 2.2). It is vectorised over a batch of trials, takes the sample
time with every call (Δt comes from the sample times, as in Eq. 2.2), clips its output to the
actuator's range and stops integrating while the output is saturated (anti-windup).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from articula.errors import ConfigError

ScheduleKind = Literal["constant", "piecewise", "fuzzy"]


@dataclass(frozen=True, eq=False)
class GainSchedule:
    """K(θ_r) of Eq. (2.4): rows [K_p, K_i, K_d] at representative points of θ_r.

    constant: one row, K for every θ_r (Eqs. 2.2-2.3). piecewise: row j on the subrange
    around points[j], the subranges meeting half-way between neighbouring points, each closed
    on the left ([0, 30), [30, 60), [60, 90] for points 15, 45, 75). fuzzy: linear between
    neighbouring points and constant beyond the outer ones, so continuous everywhere.
    Points and θ_r share one unit (degrees in chapter 2, as the book's gains are per degree).
    Gains and points are stored as read-only copies.

    Attributes:
        kind: how gains vary with θ_r: "constant", "piecewise" or "fuzzy".
        gains: rows [K_p, K_i, K_d], one per representative point, shape (rows, 3).
        points: representative points of θ_r, increasing, shape (rows,) (ignored if constant).
    """

    kind: ScheduleKind
    gains: np.ndarray
    points: np.ndarray = field(default_factory=lambda: np.zeros(1))

    def __post_init__(self) -> None:
        gains = np.atleast_2d(np.array(self.gains, dtype=float))
        points = np.atleast_1d(np.array(self.points, dtype=float))
        gains.setflags(write=False)
        points.setflags(write=False)
        object.__setattr__(self, "gains", gains)
        object.__setattr__(self, "points", points)
        if gains.ndim != 2 or gains.shape[1] != 3 or not np.all(np.isfinite(gains)):
            raise ConfigError(
                "GainSchedule.gains", f"must be finite rows [kp, ki, kd] (got shape {gains.shape})"
            )
        if self.kind == "constant":
            if gains.shape[0] != 1:
                raise ConfigError(
                    "GainSchedule.gains", f"a constant schedule has one row (got {gains.shape[0]})"
                )
            return
        if self.kind not in ("piecewise", "fuzzy"):
            raise ConfigError(
                "GainSchedule.kind",
                f"unknown schedule {self.kind!r}; use constant, piecewise or fuzzy",
            )
        if points.shape != (gains.shape[0],):
            raise ConfigError(
                "GainSchedule.points",
                f"need one point per row of gains ({gains.shape[0]}), got {points.shape}",
            )
        if not np.all(np.isfinite(points)) or np.any(np.diff(points) <= 0):
            raise ConfigError(
                "GainSchedule.points", f"must be finite and increasing (got {points.tolist()})"
            )

    @property
    def boundaries(self) -> np.ndarray:
        """Subrange boundaries of the piecewise schedule: midpoints of neighbouring points."""
        return 0.5 * (self.points[1:] + self.points[:-1])

    def __call__(self, reference: np.ndarray | float) -> np.ndarray:
        """Gains [K_p, K_i, K_d] scheduled on the reference.

        Args:
            reference: reference θ_r, scalar or array, in the unit of the points.

        Returns:
            The gains, shape reference.shape + (3,); (3,) if constant.
        """
        if self.kind == "constant":
            return self.gains[0]
        r = np.asarray(reference, dtype=float)
        if self.kind == "piecewise":
            return self.gains[np.searchsorted(self.boundaries, r, side="right")]
        return np.stack([np.interp(r, self.points, self.gains[:, j]) for j in range(3)], axis=-1)


class PID:
    """u[n] = K(θ_r)ᵀ E[n] (Eqs. 2.3-2.4), vectorised over trials, with limits and anti-windup.

    Args:
        schedule: gains K(θ_r) of Eq. (2.4).
        output_limits: actuator range (low, high) the output is clipped to (chapter 2: PWM
            counts 0-255).
        derivative_tau: time constant of an optional first-order filter on Δe/Δt (0: the raw
            difference of Eq. 2.2) [s].
        trials: number of trials controlled at once (the batch size).
    """

    def __init__(
        self,
        schedule: GainSchedule,
        output_limits: tuple[float, float] = (-np.inf, np.inf),
        derivative_tau: float = 0.0,
        trials: int = 1,
    ) -> None:
        lo, hi = output_limits
        if not lo < hi:
            raise ConfigError("PID.output_limits", f"need low < high (got {output_limits})")
        if not (np.isfinite(derivative_tau) and derivative_tau >= 0):
            raise ConfigError(
                "PID.derivative_tau", f"must be finite and >= 0 (got {derivative_tau})"
            )
        self.schedule = schedule
        self.output_limits = (float(lo), float(hi))
        self.derivative_tau = float(derivative_tau)
        self.reset(trials)

    def reset(self, trials: int) -> None:
        """Forget the past: no previous sample, zero integral.

        Args:
            trials: number of trials controlled at once (the batch size).
        """
        self.integral = np.zeros(trials)  # Σ e[i] Δt_i of Eq. (2.2)
        self.derivative = np.zeros(trials)  # (filtered) Δe_n/Δt_n of Eq. (2.2)
        self.last_error: np.ndarray | None = None
        self.last_time = 0.0

    def __call__(self, t: float, reference: np.ndarray | float, measured: np.ndarray) -> np.ndarray:
        """Control output at sample time t [s] for the given reference and measurement.

        At the first sample there is no previous one, so Δt = 0: it adds nothing to the
        integral and the derivative is zero.

        Args:
            t: sample time, increasing from call to call [s].
            reference: reference θ_r, scalar or shape (trials,).
            measured: measured output θ[n], shape (trials,).

        Returns:
            The control output u[n], clipped to the output limits, shape (trials,).
        """
        error = reference - measured  # e[n] = θ_r − θ[n]
        if self.last_error is None:
            integral = self.integral
        else:
            dt = t - self.last_time
            if not dt > 0:
                raise ConfigError(
                    "PID.t", f"sample times must increase (got {self.last_time} then {t})"
                )
            integral = self.integral + error * dt  # Σ_{i≤n} e[i] Δt_i, Eq. (2.2)
            raw = (error - self.last_error) / dt  # Δe_n / Δt_n, Eq. (2.2)
            alpha = dt / (self.derivative_tau + dt)
            self.derivative = self.derivative + alpha * (raw - self.derivative)
        gains = self.schedule(reference)
        kp, ki, kd = gains[..., 0], gains[..., 1], gains[..., 2]
        proportional = kp * error + kd * self.derivative
        u = proportional + ki * integral  # u[n] = K(θ_r)ᵀ E[n], Eqs. (2.3)-(2.4)
        lo, hi = self.output_limits
        # Anti-windup: keep the old sum where integrating would push further past a limit.
        winding = ((u > hi) & (ki * error > 0)) | ((u < lo) & (ki * error < 0))
        self.integral = np.where(winding, self.integral, integral)
        u = np.where(winding, proportional + ki * self.integral, u)
        self.last_error = error
        self.last_time = t
        return np.minimum(np.maximum(u, lo), hi)
