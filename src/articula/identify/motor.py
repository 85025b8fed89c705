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
from articula.identify.fit import (
    VALIDATION,
    Curve,
    Identification,
    fit_recordings,
    sample_period,
)
from articula.numba_cache import jit
from articula.plants.dc_motor import TABLE_4_1, MotorParams
from articula.plants.motor_rig import I_PRIMARY, OMEGA, THETA, discretize, rig_matrices

CONSTANTS = ("R", "K", "b", "J", "L")
CHANNELS = ("i_meas", "omega_meas")  # what the fit compares, with v1 as the input
DRIVER_VOLTAGE = 12.0  # [V] the H-bridge's supply (experiments/motor.py's pwm.v_max default)


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
        dt = sample_period(columns, ("v1", *CHANNELS), 100, where, "motor")
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
        The identification; its plant, a motor.current config on the single rig.
    """

    def predict(constants: dict[str, float], k: int) -> dict[str, np.ndarray]:
        """The rig model's channels for recording k."""
        current, speed = simulate(MotorParams(**constants), recordings[k], window)
        return {"i_meas": current, "omega_meas": speed}

    measured = [{c: getattr(r, c) for c in CHANNELS} for r in recordings]
    estimate = _integral_estimate(recordings, window, start)
    # L barely enters the integrals: fitted alone first, from the others' estimates.
    fit, validation, begin = fit_recordings(predict, measured, estimate, CONSTANTS, ["L"])
    motor = MotorParams(**(begin | fit.values))
    # A reference the fitted motor can hold at rest within the driver's 12 V: half its stall
    # current there (the book's 1 A at 5 rad/s is beyond a motor of twice the book's R).
    reference = {"current": round(0.5 * DRIVER_VOLTAGE / motor.R, 3), "speed": 0.0}
    plant = {
        "experiment": "motor.current",
        "rig": "single",
        "motor": motor.model_dump(),
        "reference": reference,
    }
    first = recordings[0]
    t = np.arange(first.v1.size) * first.dt
    model = predict(motor.model_dump(), 0)
    cut = t[int(t.size * (1 - VALIDATION))]
    curves = tuple(
        Curve(label, t, getattr(first, c), model[c], cut)
        for c, label in zip(CHANNELS, ("current [A]", "speed [rad/s]"), strict=True)
    )
    return Identification(fit, validation, begin, plant, curves)


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
