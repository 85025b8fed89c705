"""The motor's constants R, K, b, J, L of Eq. (4.6) from a single-rig recording: the applied
voltage v1 drives the rig model (plants.motor_rig, exact zero-order hold, as the emulator and
the firmware harness integrate it); its current is compared with the sensed one (i_meas) and
its shaft angle, differenced over the encoder's window as the rig differences its count, with
the measured speed (omega_meas)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError
from articula.identify.fit import Fit, fit_constants, nrmse
from articula.numba_cache import jit
from articula.plants.dc_motor import TABLE_4_1, MotorParams
from articula.plants.motor_rig import I_PRIMARY, OMEGA, THETA, discretize, rig_matrices

CONSTANTS = ("R", "K", "b", "J", "L")
CHANNELS = ("i_meas", "omega_meas")  # what the fit compares, with v1 as the input
VALIDATION = 0.25  # the last quarter of each recording is kept for validation


@dataclass(frozen=True)
class MotorRecording:
    """One single-rig recording, as the fit takes it.

    Attributes:
        dt: the control period [s].
        v1: the voltage applied over each period [V], shape (n,).
        i_meas: the sensed current at each period's start [A], shape (n,).
        omega_meas: the encoder's speed at each period's start [rad/s], shape (n,).
    """

    dt: float
    v1: np.ndarray
    i_meas: np.ndarray
    omega_meas: np.ndarray

    @classmethod
    def from_columns(cls, columns: Mapping[str, np.ndarray], where: str) -> MotorRecording:
        """A recording's trace columns checked for the fit.

        Args:
            columns: column name -> values: t [s], v1 [V], i_meas [A], omega_meas [rad/s] and
                v2 [V] (all zero: the load motor undriven).
            where: the recording, named in errors.

        Returns:
            The recording.
        """
        missing = [c for c in ("t", "v1", *CHANNELS) if c not in columns]
        if missing:
            raise ConfigError(where, f"not a motor recording: no {', '.join(missing)} column")
        t = np.asarray(columns["t"], dtype=float)
        if t.size < 100:
            raise ConfigError(where, f"{t.size} samples: a fit needs at least 100")
        steps = np.diff(t)
        dt = float(np.median(steps))
        if not (dt > 0 and np.allclose(steps, dt, rtol=1e-3, atol=1e-9)):
            raise ConfigError(where, "samples are not evenly spaced (a lossy line?): record again")
        if "v2" in columns and np.any(np.asarray(columns["v2"]) != 0):
            raise ConfigError(
                where,
                "the load motor was driven (v2 ≠ 0): identify on the single rig, or with the "
                "speed loop's gains at 0",
            )
        values = {c: np.asarray(columns[c], dtype=float) for c in ("v1", *CHANNELS)}
        return cls(dt, values["v1"], values["i_meas"], values["omega_meas"])


@jit()
def _simulate(Ad, Bd, v1):
    """The rig model from rest driven by v1: its state at each period's start, shape (n, 3)."""
    x = np.zeros(Ad.shape[0])
    Bd0 = np.ascontiguousarray(Bd[:, 0])
    states = np.empty((v1.size, Ad.shape[0]))
    for k in range(v1.size):
        states[k] = x
        x = Ad @ x + Bd0 * v1[k]
    return states


def simulate(
    params: MotorParams, recording: MotorRecording, window: int
) -> tuple[np.ndarray, np.ndarray]:
    """The single rig with `params` driven by the recording's voltage, from rest.

    Args:
        params: the motor's constants.
        recording: the recording whose v1 drives it.
        window: the encoder's window [samples] (0: the true speed).

    Returns:
        The current [A] and the speed the encoder would give [rad/s], each shape (n,).
    """
    Ad, Bd = discretize(*rig_matrices(params, dual=False), recording.dt)
    states = _simulate(np.ascontiguousarray(Ad), Bd, np.ascontiguousarray(recording.v1))
    if window == 0:
        return states[:, I_PRIMARY], states[:, OMEGA]
    # The rig's speed: the angle's change over the last `window` periods (fewer at the start,
    # from the angle 0 it started at), as loops.motor_current differences the count.
    theta = states[:, THETA]
    k = np.arange(theta.size)
    span = np.maximum(np.minimum(k, window), 1)
    old = np.where(k >= window, theta[np.maximum(k - window, 0)], 0.0)
    return states[:, I_PRIMARY], (theta - old) / (span * recording.dt)


@dataclass(frozen=True)
class Identification:
    """A fit and how well it predicts the data it was not fitted to.

    Attributes:
        fit: the fitted constants, their standard errors, the undetermined ones.
        validation_nrmse: channel -> NRMSE on the held-out part of every recording.
        start: the constants the fit started from (an equation-error estimate), SI.
    """

    fit: Fit
    validation_nrmse: dict[str, float]
    start: dict[str, float]

    def params(self) -> MotorParams:
        """The fitted constants as a MotorParams (an undetermined one stays at the start).

        Returns:
            The motor's constants.
        """
        return MotorParams(**(self.start | self.fit.values))


def identify_motor(
    recordings: Sequence[MotorRecording], window: int, start: MotorParams = TABLE_4_1
) -> Identification:
    """Fit R, K, b, J, L to the first three quarters of each recording; validate on the rest.

    Args:
        recordings: single-rig recordings, each from rest.
        window: the encoder's window [samples] (0: the speed is the true one).
        start: the constants an equation-error estimate falls back on where it gives no
            positive value (the book's Table 4.1 by default).

    Returns:
        The identification.
    """
    cuts = [int(r.v1.size * (1 - VALIDATION)) for r in recordings]
    # Each channel's residuals weighted by its noise (the sensor's, the encoder's), taken over
    # every recording: one that hardly moves the shaft shows the encoder no noise at all.
    i_scale, w_scale = (
        _noise([getattr(r, c)[:cut] for r, cut in zip(recordings, cuts, strict=True)])
        for c in CHANNELS
    )

    def residuals(constants: dict[str, float]) -> np.ndarray:
        """The weighted residuals on every recording's fitted part."""
        params = MotorParams(**constants)
        parts = []
        for r, cut in zip(recordings, cuts, strict=True):
            current, speed = simulate(params, r, window)
            parts += [(current - r.i_meas)[:cut] / i_scale, (speed - r.omega_meas)[:cut] / w_scale]
        return np.concatenate(parts)

    begin = _integral_estimate(recordings, window, start)
    # L barely enters the integrals: fitted alone first, from the others' estimates.
    begin |= fit_constants(residuals, begin, ["L"]).values
    fit = fit_constants(residuals, begin, CONSTANTS)
    params = MotorParams(**(begin | fit.values))
    held: dict[str, list[np.ndarray]] = {c: [[], []] for c in CHANNELS}
    for r, cut in zip(recordings, cuts, strict=True):
        current, speed = simulate(params, r, window)
        for channel, model in zip(CHANNELS, (current, speed), strict=True):
            held[channel][0].append(getattr(r, channel)[cut:])
            held[channel][1].append(model[cut:])
    validation = {c: nrmse(np.concatenate(m), np.concatenate(p)) for c, (m, p) in held.items()}
    return Identification(fit, validation, begin)


def _noise(signals: Sequence[np.ndarray]) -> float:
    """The signals' noise level: the spread of their second differences (/√6, white noise's)."""
    second = np.concatenate([np.diff(signal, 2) for signal in signals])
    level = float(np.std(second) / np.sqrt(6.0))
    spread = float(np.std(np.concatenate(signals)))
    return level if level > 0 else max(spread, 1e-12)


def _integral_estimate(
    recordings: Sequence[MotorRecording], window: int, fallback: MotorParams
) -> dict[str, float]:
    """Where the fit starts: Eq. (4.6) integrated over time and solved by linear least
    squares (an equation-error estimate: integrals average the sensors' noise out, and no
    derivative of a noisy signal is taken), ∫V = R∫i + L i + K θ and J ω + b θ = K∫i, with θ
    the measured speed's integral; each signal shifted to the encoder's window's middle."""
    electrical, mechanical = [], []
    lag = window // 2  # the windowed speed is the speed about half a window earlier
    for r in recordings:
        dt = r.dt
        charge = np.concatenate([[0.0], np.cumsum(r.i_meas[:-1]) * dt])  # ∫i [A·s]
        flux = np.concatenate([[0.0], np.cumsum(r.v1[:-1]) * dt])  # ∫V [V·s]
        speed = r.omega_meas[lag:]
        angle = np.cumsum(speed) * dt
        n = speed.size
        electrical.append((np.column_stack([charge[:n], r.i_meas[:n], angle]), flux[:n]))
        mechanical.append((speed, angle, charge[:n]))
    a = np.vstack([m for m, _ in electrical])
    y = np.concatenate([v for _, v in electrical])
    R, L, K = np.linalg.lstsq(a, y, rcond=None)[0]
    guess = fallback.model_dump()
    if K > 0:
        guess["K"] = float(K)
        a = np.vstack([np.column_stack([w, th]) for w, th, _ in mechanical])
        y = guess["K"] * np.concatenate([q for _, _, q in mechanical])
        J, b = np.linalg.lstsq(a, y, rcond=None)[0]
        guess |= {k: float(v) for k, v in (("J", J), ("b", b)) if v > 0}
    guess |= {k: float(v) for k, v in (("R", R), ("L", L)) if v > 0}
    return guess
