"""One experiment's response as a tuner sees it, and the step-response features it decides on.

A tuner needs only a `GainExperiment`: run one experiment with gains K = [K_p, K_i, K_d] and
return its `Response`. A simulated actuator and a real rig both fit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


def readonly(values: np.ndarray | float | list[float]) -> np.ndarray:
    """A read-only float copy, for arrays held by frozen dataclasses.

    Args:
        values: a number or an array-like of numbers.

    Returns:
        A float array copy of `values` with its write flag off.
    """
    array = np.array(values, dtype=float)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Response:
    """Sample times [s], reference and measured output (same unit, e.g. degrees), all (n,).

    The arrays are stored as read-only copies.

    Attributes:
        t: sample times, shape (n,) [s].
        reference: reference θ_r at each sample, shape (n,).
        measured: measured output θ at each sample, shape (n,), in the reference's unit.
    """

    t: np.ndarray
    reference: np.ndarray
    measured: np.ndarray

    def __post_init__(self) -> None:
        for name in ("t", "reference", "measured"):
            object.__setattr__(self, name, readonly(getattr(self, name)))


GainExperiment = Callable[[np.ndarray], Response]


def tracking_error(reference: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """E of Eq. (2.7) along the last axis: the mean of |θ_r[i] − θ[i]|.

    Args:
        reference: reference θ_r, shape (..., n).
        measured: measured output θ, shape (..., n), in the reference's unit.

    Returns:
        The mean absolute tracking error, shape (...), in the reference's unit.
    """
    return np.mean(np.abs(reference - measured), axis=-1)  # Eq. (2.7)


def tuning_cost(t: np.ndarray, reference: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """M of Eq. (2.5) along the last axis: the mean of |e[i]| + |Δe_i/Δt_i|.

    The first sample has no previous one, so its Δe/Δt is taken as 0 (as in the PID).

    Args:
        t: sample times, shape (n,) [s].
        reference: reference θ_r, shape (..., n).
        measured: measured output θ, shape (..., n), in the reference's unit.

    Returns:
        The cost M, shape (...).
    """
    e = reference - measured
    slope = np.zeros_like(e)
    slope[..., 1:] = np.diff(e, axis=-1) / np.diff(t)
    return np.mean(np.abs(e) + np.abs(slope), axis=-1)  # Eq. (2.5)


@dataclass(frozen=True, eq=False)
class StepFeatures:
    """What the manual procedure looks at in a step response from rest (response units).

    Attributes:
        overshoot: largest excursion past the target, >= 0.
        steady_state_error: |target − mean output| over the last quarter of the run.
        peak_times: times of the extremes of each swing about the final level beyond the
            band, shape (s,) [s].
        peak_sizes: |output − final level| at those extremes, shape (s,).
    """

    overshoot: float
    steady_state_error: float
    peak_times: np.ndarray
    peak_sizes: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "peak_times", readonly(self.peak_times))
        object.__setattr__(self, "peak_sizes", readonly(self.peak_sizes))

    @property
    def oscillates(self) -> bool:
        """At least two swings about the final level beyond the noise band."""
        return self.peak_sizes.size >= 2

    @property
    def decay(self) -> float:
        """Size of the last swing over the first; nan without two swings."""
        return float(self.peak_sizes[-1] / self.peak_sizes[0]) if self.oscillates else float("nan")

    @property
    def converging(self) -> bool:
        """Oscillating with swings that shrink."""
        return self.oscillates and self.decay < 1.0

    def sustained(self, keep: float = 0.8) -> bool:
        """At least three swings, the last two still `keep` of the first two's size or more.

        Swings are compared in pairs (one up, one down) because a driven soft actuator swings
        further one way than the other.

        Args:
            keep: fraction of the first two swings' mean size the last two must keep.

        Returns:
            True if the oscillation is sustained.
        """
        sizes = self.peak_sizes
        return sizes.size >= 3 and float(np.mean(sizes[-2:])) >= keep * float(np.mean(sizes[:2]))

    @property
    def period(self) -> float:
        """Oscillation period [s]: twice the mean time between successive swings; nan if none."""
        return float(2 * np.mean(np.diff(self.peak_times))) if self.oscillates else float("nan")


def step_features(response: Response, band: float) -> StepFeatures:
    """Features of a step response from rest.

    Args:
        response: the step response; its target is the reference's last value.
        band: noise band about a level; swings inside it do not count (response units).

    Returns:
        The overshoot, steady-state error and the swings about the final level.
    """
    target = float(response.reference[-1])
    y = response.measured
    step = target - float(y[0]) or 1.0
    final = float(np.mean(y[-max(y.size // 4, 1) :]))
    overshoot = max(0.0, float(np.max((y - target) * np.sign(step))))
    deviation = y - final
    reached = np.flatnonzero(np.sign(deviation) != np.sign(deviation[0]))
    times: list[float] = []
    sizes: list[float] = []
    if reached.size:
        sign = 0
        for n in range(int(reached[0]), y.size):
            s = 1 if deviation[n] > band else -1 if deviation[n] < -band else 0
            if s == 0:
                continue
            if s != sign:
                times.append(float(response.t[n]))
                sizes.append(abs(float(deviation[n])))
                sign = s
            elif abs(deviation[n]) > sizes[-1]:
                times[-1], sizes[-1] = float(response.t[n]), abs(float(deviation[n]))
    return StepFeatures(overshoot, abs(target - final), np.array(times), np.array(sizes))
