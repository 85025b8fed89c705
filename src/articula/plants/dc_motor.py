"""Brushed DC motor model of chapter 4: state space, transfer matrix, steady state."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from articula.errors import InfeasibleError
from articula.validation import StrictModel

# The book gives no armature inductance; 10 mH is typical of a 12 V gear-motor with
# R ≈ 8 Ω and keeps the book's K_p = 10 current loop stable at 1 kHz (docs/deviations.md).
DEFAULT_INDUCTANCE = 10e-3


# Any real motor's constants lie within [1e-9, 1e6] in SI units; beyond, 1/J or R/L overflow.
Constant = Annotated[float, Field(ge=1e-9, le=1e6, allow_inf_nan=False)]


class MotorParams(StrictModel):
    """Motor constants in SI: R [Ω], K = K_t = K_e [N·m/A], b [N·m·s/rad], J [kg·m²], L [H].

    Attributes:
        R: armature resistance [Ω].
        K: torque constant K_t, equal to the back-emf constant K_e [N·m/A] = [V·s/rad].
        b: viscous friction of the shaft [N·m·s/rad].
        J: rotor (and load) inertia [kg·m²].
        L: armature inductance [H]; not in the book, 10 mH by default (docs/deviations.md).
    """

    R: Constant
    K: Constant
    b: Annotated[float, Field(ge=0, le=1e6, allow_inf_nan=False)]
    J: Constant
    L: Constant = DEFAULT_INDUCTANCE


# Table 4.1: the single motor.
TABLE_4_1 = MotorParams(R=8.35, K=0.355, b=0.0016, J=0.1)
# Table 4.2: the primary motor re-estimated with the secondary coupled to its shaft.
TABLE_4_2 = MotorParams(R=8.35, K=0.4485, b=0.002, J=0.1)
PRESETS: dict[str, MotorParams] = {"table4.1": TABLE_4_1, "table4.2": TABLE_4_2}


def state_space(p: MotorParams) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of Eq. (4.6); states [ω, i], inputs [τ_ex, V].

    Args:
        p: motor constants.

    Returns:
        A: state matrix, shape (2, 2), for x = [ω [rad/s], i [A]].
        B: input matrix, shape (2, 2), for u = [τ_ex [N·m], V [V]].
    """
    A = np.array([[-p.b / p.J, p.K / p.J], [-p.K / p.L, -p.R / p.L]])  # Eq. (4.6)
    B = np.array([[1.0 / p.J, 0.0], [0.0, 1.0 / p.L]])  # Eq. (4.6)
    return A, B


def transfer_matrix(p: MotorParams) -> dict[str, tuple[list[float], list[float]]]:
    """The four entries of G(s), Eq. (4.7), as (num, den), highest power of s first.

    Args:
        p: motor constants.

    Returns:
        Entry name ("omega/tau_ex", "omega/V", "i/tau_ex", "i/V") -> (numerator, denominator)
            polynomial coefficients in s, sharing the denominator (Js + b)(Ls + R) + K².
    """
    # Eq. (4.7): common denominator (Js + b)(Ls + R) + K².
    den = [p.J * p.L, p.J * p.R + p.b * p.L, p.b * p.R + p.K**2]
    return {
        "omega/tau_ex": ([p.L, p.R], den),
        "omega/V": ([p.K], den),
        "i/tau_ex": ([-p.K], den),
        "i/V": ([p.J, p.b], den),
    }


def poles(p: MotorParams) -> np.ndarray:
    """Open-loop poles [1/s]: the eigenvalues of A in Eq. (4.6).

    Args:
        p: motor constants.

    Returns:
        The two poles, shape (2,) [1/s] (complex when the motor is underdamped).
    """
    return np.linalg.eigvals(state_space(p)[0])


def steady_state(p: MotorParams, voltage: float, torque: float = 0.0) -> tuple[float, float]:
    """(ω_ss [rad/s], i_ss [A]) for constant V [V] and τ_ex [N·m], Eq. (4.8).

    Args:
        p: motor constants.
        voltage: constant armature voltage V [V].
        torque: constant external torque τ_ex on the shaft [N·m]; negative loads the motor.

    Returns:
        omega: steady-state speed ω_ss [rad/s].
        current: steady-state current i_ss [A].
    """
    d = p.b * p.R + p.K**2
    omega = (p.R * torque + p.K * voltage) / d  # Eq. (4.8)
    current = (-p.K * torque + p.b * voltage) / d  # Eq. (4.8); τ_ex < 0 raises it, Eq. (4.10)
    return omega, current


def current_at_speed(p: MotorParams, voltage: float, omega: float) -> float:
    """Quasi-static current [A] at speed ω [rad/s] with L ≈ 0, Eq. (4.11).

    Args:
        p: motor constants.
        voltage: armature voltage V [V].
        omega: shaft speed ω [rad/s].

    Returns:
        The armature current i = (V − K ω) / R [A].
    """
    return (voltage - p.K * omega) / p.R  # Eq. (4.11)


def critical_speed(p: MotorParams, voltage: float, current: float) -> float:
    """Speed ω_c [rad/s] below which the motor can still draw `current` [A] at `voltage` [V].

    Args:
        p: motor constants.
        voltage: largest armature voltage available [V].
        current: current the motor must draw [A].

    Returns:
        The critical speed ω_c = (V − i R) / K [rad/s].

    Raises:
        InfeasibleError: when `current` needs more than `voltage` even at standstill.
    """
    omega_c = (voltage - current * p.R) / p.K  # ω_c = (V − i_ss R) / K, Sect. 4.3.2
    if omega_c <= 0:
        raise InfeasibleError(
            f"--current/--voltage: {current} A needs more than {voltage} V even at standstill "
            f"(i·R = {current * p.R:.3g} V); lower the current or raise the voltage"
        )
    return omega_c


def feedforward_voltage(p: MotorParams, current: float, omega: float) -> float:
    """Bias voltage [V] that holds `current` [A] at speed `omega` [rad/s], Eq. (4.13).

    Args:
        p: motor constants.
        current: current to hold [A].
        omega: shaft speed [rad/s].

    Returns:
        The feed-forward voltage i R + K ω [V].
    """
    return current * p.R + p.K * omega  # Eq. (4.13)
