"""Single- and dual-motor rigs of Sect. 4.3 as linear state-space models, continuous and ZOH."""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from articula.plants.dc_motor import MotorParams

# State order of every rig model: shaft angle θ [rad], shaft speed ω [rad/s], primary current
# i₁ [A] and, on the dual rig, secondary current i₂ [A]. Inputs: V₁ [V], V₂ [V].
THETA, OMEGA, I_PRIMARY, I_SECONDARY = 0, 1, 2, 3


def rig_matrices(p: MotorParams, dual: bool) -> tuple[np.ndarray, np.ndarray]:
    """Continuous (A, B) of the rig; inputs (V₁, V₂) (V₂ has no effect on the single rig).

    Args:
        p: motor constants (Table 4.1 for the single rig, Table 4.2 for the dual one).
        dual: True for the dual rig (a secondary motor, reversed, on the same shaft).

    Returns:
        A: state matrix, shape (n, n), states [θ [rad], ω [rad/s], i₁ [A]] and, with
            `dual`, i₂ [A] (n = 3 or 4).
        B: input matrix, shape (n, 2), inputs (V₁, V₂) [V].
    """
    n = 4 if dual else 3
    A = np.zeros((n, n))
    B = np.zeros((n, 2))
    A[THETA, OMEGA] = 1.0
    # Eq. (4.5a) on the shared shaft: J ω̇ = K i₁ − b ω + τ_ex; on the dual rig J and b are the
    # re-estimated values of Table 4.2 for both rotors together.
    A[OMEGA, OMEGA] = -p.b / p.J
    A[OMEGA, I_PRIMARY] = p.K / p.J
    # Eq. (4.5b) for the primary: L di₁/dt = V₁ − R i₁ − K ω.
    A[I_PRIMARY, OMEGA] = -p.K / p.L
    A[I_PRIMARY, I_PRIMARY] = -p.R / p.L
    B[I_PRIMARY, 0] = 1.0 / p.L
    if dual:
        # The secondary is wired with opposite polarity: its torque on the shaft is
        # τ_ex = −K i₂ and its back-emf seen in its own circuit is −K ω, Eq. (4.5) mirrored.
        A[OMEGA, I_SECONDARY] = -p.K / p.J
        A[I_SECONDARY, OMEGA] = p.K / p.L
        A[I_SECONDARY, I_SECONDARY] = -p.R / p.L
        B[I_SECONDARY, 1] = 1.0 / p.L
    return A, B


def discretize(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation (Ad, Bd) for a sample time dt [s].

    Args:
        A: continuous state matrix, shape (n, n).
        B: continuous input matrix, shape (n, m).
        dt: sample time [s].

    Returns:
        Ad: discrete state matrix exp(A dt), shape (n, n).
        Bd: discrete input matrix for inputs held over each sample, shape (n, m).
    """
    n, m = B.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = A
    aug[:n, n:] = B
    phi = expm(aug * dt)
    return phi[:n, :n], phi[:n, n:]
