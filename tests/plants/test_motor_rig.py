"""plants/motor_rig.py: single and dual motor rigs of Sect. 4.3, continuous and ZOH models, against
the motor of Eq. (4.6), hand solutions, an ODE solver and scipy."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.signal import cont2discrete

from articula.plants.dc_motor import (
    TABLE_4_1,
    TABLE_4_2,
    MotorParams,
    feedforward_voltage,
    state_space,
    steady_state,
)
from articula.plants.motor_rig import discretize, rig_matrices
from tests.plants.helpers import motor_params

PRESETS = [TABLE_4_1, TABLE_4_2, MotorParams(R=2.0, K=0.05, b=0.0, J=1e-3, L=5e-4)]
PRESET_IDS = ["table4.1", "table4.2", "small"]


def dual_rig_rhs(p: MotorParams, v1: float, v2: float):
    """Shared shaft, secondary reversed, written out by hand; state [θ, ω, i₁, i₂]."""

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        _theta, omega, i1, i2 = x
        return np.array(
            [
                omega,
                (p.K * i1 - p.K * i2 - p.b * omega) / p.J,
                (v1 - p.R * i1 - p.K * omega) / p.L,
                (v2 - p.R * i2 + p.K * omega) / p.L,
            ]
        )

    return rhs


def dual_steady_state(p: MotorParams, v1: float, v2: float) -> tuple[float, float, float]:
    """(ω, i₁, i₂) at rest from the three balance equations, eliminated by hand.

    i₁ = (V₁ − Kω)/R and i₂ = (V₂ + Kω)/R put into K i₁ − K i₂ = b ω give
    ω = K (V₁ − V₂) / (2K² + bR).
    """
    omega = p.K * (v1 - v2) / (2 * p.K**2 + p.b * p.R)
    return omega, (v1 - p.K * omega) / p.R, (v2 + p.K * omega) / p.R


# ------------------------------------------------------------------------- continuous models


@pytest.mark.parametrize("p", PRESETS, ids=PRESET_IDS)
def test_single_rig_is_the_eq_4_6_motor_plus_an_angle(p: MotorParams):
    A, B = rig_matrices(p, dual=False)
    A_m, B_m = state_space(p)
    assert A.shape == (3, 3)
    assert B.shape == (3, 2)
    np.testing.assert_array_equal(A[0], [0.0, 1.0, 0.0])  # θ' = ω
    np.testing.assert_allclose(A[1:, 1:], A_m)
    np.testing.assert_allclose(B[1:, 0], B_m[:, 1])  # V₁ enters like V of Eq. (4.6)
    np.testing.assert_array_equal(B[:, 1], 0.0)  # no secondary on the single rig
    np.testing.assert_array_equal(A[:, 0], 0.0)  # nothing depends on the angle


@pytest.mark.parametrize("p", PRESETS, ids=PRESET_IDS)
def test_single_rig_steady_state_is_eq_4_8(p: MotorParams):
    A, B = rig_matrices(p, dual=False)
    x = np.linalg.solve(A[1:, 1:], -B[1:] @ np.array([12.0, 0.0]))
    np.testing.assert_allclose(x, steady_state(p, 12.0, 0.0), rtol=1e-10)


@pytest.mark.parametrize("p", PRESETS, ids=PRESET_IDS)
@pytest.mark.parametrize(("v1", "v2"), [(12.0, 0.0), (10.5925, 5.9), (-3.0, 4.0), (0.0, 12.0)])
def test_dual_rig_steady_state_against_hand_solution(p: MotorParams, v1: float, v2: float):
    A, B = rig_matrices(p, dual=True)
    assert A.shape == (4, 4)
    # Drop the angle, which integrates ω forever, and solve 0 = A x + B u.
    x = np.linalg.solve(A[1:, 1:], -B[1:] @ np.array([v1, v2]))
    np.testing.assert_allclose(x, dual_steady_state(p, v1, v2), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("p", [TABLE_4_2, PRESETS[2]], ids=["table4.2", "small"])
def test_dual_rig_long_simulation_reaches_the_hand_solution(p: MotorParams):
    v1, v2 = 10.0, 6.0
    A, B = rig_matrices(p, dual=True)
    rhs = dual_rig_rhs(p, v1, v2)
    jac = np.array(
        [
            [0, 1, 0, 0],
            [0, -p.b / p.J, p.K / p.J, -p.K / p.J],
            [0, -p.K / p.L, -p.R / p.L, 0],
            [0, p.K / p.L, 0, -p.R / p.L],
        ]
    )
    # The hand-written ODE and the rig matrices are the same linear system.
    x0 = np.array([0.3, -1.0, 0.2, 0.5])
    np.testing.assert_allclose(A @ x0 + B @ [v1, v2], rhs(0.0, x0), rtol=1e-12)
    slow = 1.0 / np.min(np.abs(np.linalg.eigvals(jac[1:, 1:]).real))
    sol = solve_ivp(
        rhs, (0, 40 * slow), np.zeros(4), method="Radau", jac=jac, rtol=1e-10, atol=1e-12
    )
    np.testing.assert_allclose(sol.y[1:, -1], dual_steady_state(p, v1, v2), rtol=1e-6)


def test_dual_rig_feedforward_holds_current_at_held_speed():
    # With V₁ = V_bias of Eq. (4.13) and the secondary holding ω_ss, the primary carries i_ss.
    p = TABLE_4_2
    i_ss, w_ss = 1.0, 5.0
    v1 = feedforward_voltage(p, i_ss, w_ss)
    v2 = v1 - w_ss * (2 * p.K**2 + p.b * p.R) / p.K  # the V₂ that gives ω = ω_ss
    A, B = rig_matrices(p, dual=True)
    omega, i1, i2 = np.linalg.solve(A[1:, 1:], -B[1:] @ np.array([v1, v2]))
    assert omega == pytest.approx(w_ss)
    assert i1 == pytest.approx(i_ss)
    # The secondary brakes: torque balance K i₁ − K i₂ = b ω, by hand.
    assert i2 == pytest.approx(i_ss - p.b * w_ss / p.K)
    assert v2 == pytest.approx(p.R * i2 - p.K * w_ss)


@settings(max_examples=50, deadline=None)
@given(p=motor_params(), dual=st.booleans())
def test_rig_is_passive_energy_only_dissipates(p: MotorParams, dual: bool):
    # Stored energy E = ½Jω² + ½L Σi²: with both supplies shorted, dE/dt = −bω² − R Σi²,
    # i.e. sym(P A) = −diag(b, R, R) on [ω, i₁, i₂] with P = diag(J, L, L). The motor
    # coupling terms (and the reversed secondary's signs) must cancel exactly.
    A, _ = rig_matrices(p, dual)
    A = A[1:, 1:]
    n = A.shape[0]
    P = np.diag([p.J] + [p.L] * (n - 1))
    sym = 0.5 * (P @ A + A.T @ P)
    expected = -np.diag([p.b] + [p.R] * (n - 1))
    np.testing.assert_allclose(sym, expected, atol=1e-9 * max(p.R, p.K, 1.0))


# --------------------------------------------------------------------------- discretisation


@pytest.mark.parametrize("p", PRESETS, ids=PRESET_IDS)
@pytest.mark.parametrize("dual", [False, True], ids=["single", "dual"])
@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2])
def test_discretize_matches_scipy_zoh(p: MotorParams, dual: bool, dt: float):
    A, B = rig_matrices(p, dual)
    Ad, Bd = discretize(A, B, dt)
    n = A.shape[0]
    ref = cont2discrete((A, B, np.eye(n), np.zeros((n, 2))), dt, method="zoh")
    np.testing.assert_allclose(Ad, ref[0], rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(Bd, ref[1], rtol=1e-10, atol=1e-13)


@settings(max_examples=20, deadline=None)
@given(
    p=motor_params(),
    dual=st.booleans(),
    dt=st.floats(1e-4, 1e-2),
    v=st.tuples(st.floats(-12, 12), st.floats(-12, 12)),
)
def test_discrete_step_equals_integrated_ode(p: MotorParams, dual: bool, dt: float, v):
    # One ZOH step with constant inputs is the exact solution of the ODE over dt.
    A, B = rig_matrices(p, dual)
    Ad, Bd = discretize(A, B, dt)
    n = A.shape[0]
    x0 = np.linspace(-1.0, 1.0, n)
    u = np.array(v)
    sol = solve_ivp(
        lambda _t, x: A @ x + B @ u, (0, dt), x0, method="BDF", jac=A, rtol=1e-11, atol=1e-13
    )
    scale = 1.0 + np.abs(sol.y[:, -1]).max()
    np.testing.assert_allclose(Ad @ x0 + Bd @ u, sol.y[:, -1], rtol=1e-7, atol=1e-9 * scale)


def test_discrete_rig_fixed_point_is_the_continuous_steady_state():
    p = TABLE_4_2
    Ad, Bd = discretize(*rig_matrices(p, dual=True), 1e-3)
    u = np.array([10.0, 6.0])
    x = np.linalg.solve(np.eye(3) - Ad[1:, 1:], Bd[1:] @ u)
    np.testing.assert_allclose(x, dual_steady_state(p, *u), rtol=1e-8)
