"""plants/dc_motor.py: the DC motor of Sect. 4.2 (Eqs. 4.5-4.13) against independent oracles.

Oracles: python-control's state-space -> transfer-function conversion, a numerical ODE
integration of Eq. (4.5) written out by hand, and the book's printed numbers.
"""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from articula.errors import ConfigError, InfeasibleError
from articula.plants.dc_motor import (
    TABLE_4_1,
    TABLE_4_2,
    MotorParams,
    critical_speed,
    current_at_speed,
    feedforward_voltage,
    poles,
    state_space,
    steady_state,
    transfer_matrix,
)
from articula.validation import parse_model
from tests.plants.helpers import motor_params

# (transfer_matrix key) -> (output index, input index); outputs [ω, i], inputs [τ_ex, V].
ENTRIES = {
    "omega/tau_ex": (0, 0),
    "omega/V": (0, 1),
    "i/tau_ex": (1, 0),
    "i/V": (1, 1),
}


def _motor_ode(p: MotorParams, voltage: float, torque: float):
    """Eq. (4.5) written out by hand: J ω' = K i − b ω + τ_ex, L i' = V − R i − K ω."""

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        omega, i = x
        return np.array(
            [
                (p.K * i - p.b * omega + torque) / p.J,
                (voltage - p.R * i - p.K * omega) / p.L,
            ]
        )

    jac = np.array([[-p.b / p.J, p.K / p.J], [-p.K / p.L, -p.R / p.L]])
    return rhs, jac


def _slowest_time_constant(jac: np.ndarray) -> float:
    return 1.0 / np.min(np.abs(np.linalg.eigvals(jac).real))


def _simulate_to_rest(p: MotorParams, voltage: float, torque: float) -> np.ndarray:
    """[ω, i] after a long constant-input run from rest (many slowest time constants)."""
    rhs, jac = _motor_ode(p, voltage, torque)
    t_end = 40.0 * _slowest_time_constant(jac)
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 0.0], method="Radau", jac=jac, rtol=1e-9, atol=1e-11)
    assert sol.success
    return sol.y[:, -1]


def _forced_response_to_rest(p: MotorParams, voltage: float, torque: float) -> np.ndarray:
    """[ω, i] at the end of a long python-control simulation of Eq. (4.5) from rest."""
    _, jac = _motor_ode(p, voltage, torque)
    B = np.array([[1.0 / p.J, 0.0], [0.0, 1.0 / p.L]])  # inputs [τ_ex, V], by hand
    sys = control.ss(jac, B, np.eye(2), np.zeros((2, 2)))
    T = np.linspace(0.0, 40.0 * _slowest_time_constant(jac), 2001)
    U = np.vstack([np.full(T.size, torque), np.full(T.size, voltage)])
    return np.asarray(control.forced_response(sys, T, U).outputs)[:, -1]


def _normalised(num: np.ndarray, den: np.ndarray, length: int) -> tuple[np.ndarray, np.ndarray]:
    """Divide by the leading denominator coefficient and left-pad the numerator to `length`."""
    num = np.atleast_1d(np.asarray(num, dtype=float).squeeze())
    den = np.atleast_1d(np.asarray(den, dtype=float).squeeze())
    lead = den[0]
    num = np.concatenate([np.zeros(length - num.size), num]) / lead
    return num, den / lead


# ---------------------------------------------------------------- state space and G(s), Eq. 4.7


def test_state_space_matches_eq_4_6_for_table_4_1():
    A, B = state_space(TABLE_4_1)
    L = TABLE_4_1.L
    np.testing.assert_allclose(A, [[-0.0016 / 0.1, 0.355 / 0.1], [-0.355 / L, -8.35 / L]])
    np.testing.assert_allclose(B, [[1 / 0.1, 0.0], [0.0, 1 / L]])


@settings(max_examples=50, deadline=None)
@given(p=motor_params())
def test_transfer_matrix_matches_python_control_ss2tf(p: MotorParams):
    A, B = state_space(p)
    G = transfer_matrix(p)
    assert set(G) == set(ENTRIES)
    for key, (row, col) in ENTRIES.items():
        ref = control.ss2tf(control.ss(A, B[:, [col]], np.eye(2)[[row], :], 0.0))
        ref_num, ref_den = _normalised(ref.num[0][0], ref.den[0][0], 3)
        num, den = _normalised(*G[key], 3)
        # ss2tf builds both polynomials from eigenvalues that can lie decades apart (R/L
        # against K²/(JR)), and the numerator by cancellation against the denominator, so
        # its round-off scales with the largest coefficient; the frequency-response test
        # below checks the small coefficients tightly.
        scale = max(np.abs(ref_num).max(), np.abs(ref_den).max())
        np.testing.assert_allclose(den, ref_den, rtol=1e-7, atol=1e-9 * scale)
        np.testing.assert_allclose(num, ref_num, rtol=1e-7, atol=1e-9 * scale)


@settings(max_examples=50, deadline=None)
@given(p=motor_params())
def test_transfer_matrix_frequency_response_matches_state_space(p: MotorParams):
    A, B = state_space(p)
    sys = control.ss(A, B, np.eye(2), np.zeros((2, 2)))
    G = transfer_matrix(p)
    for s in (0.0, 0.3j, 1.0 + 2.0j, 50j, -0.5 + 300j, 1e4j):
        ref = np.asarray(sys(s))
        for key, (row, col) in ENTRIES.items():
            num, den = G[key]
            value = np.polyval(num, s) / np.polyval(den, s)
            assert value == pytest.approx(ref[row, col], rel=1e-7, abs=1e-12 * abs(ref).max())


def test_poles_are_roots_of_the_eq_4_7_denominator():
    for p in (TABLE_4_1, TABLE_4_2):
        # Characteristic polynomial of Eq. (4.7): (Js + b)(Ls + R) + K², expanded by hand.
        char = [p.J * p.L, p.J * p.R + p.b * p.L, p.b * p.R + p.K**2]
        np.testing.assert_allclose(np.sort_complex(poles(p)), np.sort_complex(np.roots(char)))
        assert np.all(poles(p).real < 0)


# ------------------------------------------------------------------ steady state, Eqs. 4.8-4.10


def test_steady_state_table_4_1_per_volt_from_eq_4_8():
    # By hand from Table 4.1: bR + K² = 0.0016·8.35 + 0.355² = 0.139385.
    omega, i = steady_state(TABLE_4_1, 1.0)
    assert omega == pytest.approx(0.355 / 0.139385, rel=1e-12)
    assert i == pytest.approx(0.0016 / 0.139385, rel=1e-12)


@pytest.mark.parametrize("p", [TABLE_4_1, TABLE_4_2], ids=["table4.1", "table4.2"])
@pytest.mark.parametrize(
    ("voltage", "torque"), [(12.0, 0.0), (12.0, -0.3), (5.0, 0.2), (-7.0, -0.1), (0.0, -0.5)]
)
def test_steady_state_matches_long_simulation(p: MotorParams, voltage: float, torque: float):
    omega, i = steady_state(p, voltage, torque)
    sim = _simulate_to_rest(p, voltage, torque)
    np.testing.assert_allclose([omega, i], sim, rtol=1e-6, atol=1e-9)


@settings(max_examples=50, deadline=None)
@given(
    p=motor_params(),
    voltage=st.floats(-24.0, 24.0),
    torque=st.floats(-1.0, 1.0),
)
def test_steady_state_matches_long_python_control_simulation(
    p: MotorParams, voltage: float, torque: float
):
    omega, i = steady_state(p, voltage, torque)
    sim = _forced_response_to_rest(p, voltage, torque)
    # Stiff corners (R/L ~ 1e5 /s against K²/(JR) ~ 1e-5 /s) cost the exponential
    # discretisation some digits; any error in Eq. (4.8) itself is O(1).
    scale = 1.0 + np.abs(sim).max()
    np.testing.assert_allclose([omega, i], sim, rtol=1e-5, atol=1e-7 * scale)


@pytest.mark.parametrize("p", [TABLE_4_1, TABLE_4_2], ids=["table4.1", "table4.2"])
def test_negative_external_torque_raises_current_eq_4_10(p: MotorParams):
    _, i_free = steady_state(p, 12.0, 0.0)
    _, i_loaded = steady_state(p, 12.0, -0.4)
    assert i_loaded > i_free
    # The simulated rig agrees on the ordering and on the value.
    sim_free = _simulate_to_rest(p, 12.0, 0.0)[1]
    sim_loaded = _simulate_to_rest(p, 12.0, -0.4)[1]
    assert sim_loaded > sim_free
    assert i_loaded == pytest.approx(sim_loaded, rel=1e-6)
    # Eq. (4.10) with τ' = 0.4 N·m, by hand.
    assert i_loaded == pytest.approx((p.K * 0.4 + p.b * 12.0) / (p.b * p.R + p.K**2), rel=1e-12)


def test_steady_state_power_balance():
    # Electrical power in = copper loss + friction loss + work done against τ_ex.
    p = TABLE_4_2
    for voltage, torque in ((12.0, 0.0), (12.0, -0.3), (3.0, 0.1)):
        omega, i = steady_state(p, voltage, torque)
        lhs = voltage * i
        rhs = p.R * i**2 + p.b * omega**2 - torque * omega
        assert lhs == pytest.approx(rhs, rel=1e-9, abs=1e-12)


# --------------------------------------------------------- critical speed, Eq. 4.11, Sect. 4.3.2


def test_critical_speed_book_value():
    assert round(critical_speed(TABLE_4_2, 12.0, 1.0), 4) == 8.1382


@pytest.mark.parametrize("current", [12.0 / 8.35, 1.5, 3.0])
def test_critical_speed_infeasible_current(current: float):
    with pytest.raises(InfeasibleError):
        critical_speed(TABLE_4_2, 12.0, current)


@settings(max_examples=50, deadline=None)
@given(
    p=motor_params(),
    voltage=st.floats(0.5, 48.0),
    fraction=st.floats(0.01, 0.99),
)
def test_current_at_speed_consistent_with_critical_speed(
    p: MotorParams, voltage: float, fraction: float
):
    current = fraction * voltage / p.R  # reachable at standstill
    omega_c = critical_speed(p, voltage, current)
    assert omega_c > 0
    assert current_at_speed(p, voltage, omega_c) == pytest.approx(current, rel=1e-9, abs=1e-12)
    # Fig. 4.3: the quasi-static current falls with speed, so below ω_c it exceeds `current`.
    assert current_at_speed(p, voltage, 0.5 * omega_c) > current
    assert current_at_speed(p, voltage, 1.5 * omega_c) < current
    # At standstill all the voltage drops across R.
    assert current_at_speed(p, voltage, 0.0) == pytest.approx(voltage / p.R)


def test_current_at_speed_is_l_to_zero_limit_of_the_rig():
    # With the speed held fixed, Eq. (4.5b) settles at i = (V − Kω)/R whatever L is.
    p = TABLE_4_2
    omega = 5.0
    sol = solve_ivp(
        lambda _t, i: (12.0 - p.R * i - p.K * omega) / p.L,
        (0.0, 50 * p.L / p.R),
        [0.0],
        rtol=1e-10,
        atol=1e-12,
    )
    assert current_at_speed(p, 12.0, omega) == pytest.approx(sol.y[0, -1], rel=1e-8)


def test_feedforward_voltage_eq_4_13_holds_the_current():
    p = TABLE_4_2
    v = feedforward_voltage(p, 1.0, 5.0)
    assert v == pytest.approx(8.35 + 0.4485 * 5.0)
    assert current_at_speed(p, v, 5.0) == pytest.approx(1.0)
    assert critical_speed(p, v, 1.0) == pytest.approx(5.0)


# ------------------------------------------------------------------------------ parameter model


def test_motor_params_reject_non_physical_values():
    good = {"R": 8.35, "K": 0.4485, "b": 0.0, "J": 0.1, "L": 0.01}
    assert parse_model(MotorParams, good).b == 0.0
    for key, bad in (("R", 0.0), ("K", -0.1), ("J", 0.0), ("L", -1e-3), ("b", -1e-4)):
        with pytest.raises(ConfigError):
            parse_model(MotorParams, {**good, key: bad})
    with pytest.raises(ConfigError):
        parse_model(MotorParams, {**good, "R": math.nan})
