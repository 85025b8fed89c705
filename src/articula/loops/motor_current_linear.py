"""The chapter-4 current loop linearised (ideal sensor and driver), built with python-control."""

from __future__ import annotations

import control as ct
import numpy as np

from articula.loops.motor_current import LoopSettings
from articula.plants.motor_rig import I_PRIMARY, OMEGA, THETA


def pi_discrete(kp: float, ki: float, dt: float) -> ct.TransferFunction:
    """The loop's PI, u = kp·e + ki·Σe·dt with the sum including the present error.

    Args:
        kp: proportional gain (e.g. [V/A]).
        ki: integral gain (e.g. [V/(A·s)]).
        dt: sample time [s].

    Returns:
        The discrete PI ((kp + ki dt) z − kp) / (z − 1).
    """
    return ct.tf([kp + ki * dt, -kp], [1.0, -1.0], dt)


def moving_average_tf(order: int, dt: float) -> ct.TransferFunction:
    """Mean of the last `order` samples, Eq. (4.17) as a mean: Σ z^-j / k.

    Args:
        order: number k of samples averaged.
        dt: sample time [s].

    Returns:
        The discrete moving-average filter.
    """
    num = np.ones(order) / order
    den = np.zeros(order)
    den[0] = 1.0
    return ct.tf(num, den, dt)


def closed_loop(Ad: np.ndarray, Bd: np.ndarray, s: LoopSettings) -> ct.StateSpace:
    """Discrete closed loop from the current reference r [A] to the motor current i [A].

    Args:
        Ad: ZOH state matrix of the rig, shape (n, n), states [θ, ω, i₁(, i₂)].
        Bd: ZOH input matrix of the rig, shape (n, 2), inputs [V₁, V₂].
        s: the loop's gains, filter order and control period (sensor and PWM ignored).

    Returns:
        The closed loop r -> i with plant, moving average, current PI and, on the dual rig,
            the speed PI, the shaft angle dropped.
    """
    # The shaft angle drives nothing in the linear loop (ideal encoder): drop it, leaving its
    # pole at z = 1 out of the stability test and the DC gain.
    keep = np.arange(Ad.shape[0]) != THETA
    Ad, Bd = Ad[np.ix_(keep, keep)], Bd[keep]
    C = np.zeros((2, Ad.shape[0]))
    C[0, OMEGA - 1] = 1.0
    C[1, I_PRIMARY - 1] = 1.0
    plant = ct.ss(Ad, Bd, C, np.zeros((2, 2)), s.dt, inputs=["v1", "v2"], outputs=["omega", "i"])
    filt = ct.ss(moving_average_tf(s.filter_order, s.dt), inputs="i", outputs="i_f")
    # Eq. (4.14) about the operating point; the constant bias of Eq. (4.13) drops out.
    error = ct.summing_junction(inputs=["r", "-i_f"], output="e")
    current_pi = ct.ss(pi_discrete(s.kp, s.ki, s.dt), inputs="e", outputs="v1")
    # Eq. (4.12) through the reversed secondary: v2 = PI_ω·ω about the operating point.
    speed_pi = ct.ss(
        pi_discrete(s.kp_speed, s.ki_speed, s.dt) * (1.0 if s.dual else 0.0),
        inputs="omega",
        outputs="v2",
    )
    return ct.interconnect(
        [plant, filt, error, current_pi, speed_pi], inplist=["r"], outlist=["i"], dt=s.dt
    )


def is_stable(sys: ct.StateSpace) -> bool:
    """True when every closed-loop pole lies strictly inside the unit circle.

    Args:
        sys: a discrete-time system.

    Returns:
        Whether the system is asymptotically stable.
    """
    return bool(np.all(np.abs(sys.poles()) < 1.0))


def bandwidth(sys: ct.StateSpace, dt: float, points: int = 400) -> float:
    """First frequency [rad/s] where |i/r| falls 3 dB below its DC gain; inf below Nyquist.

    The crossing is bracketed on a log grid, then refined by bisection to 1e-6 relative.

    Args:
        sys: the discrete closed loop r -> i (closed_loop).
        dt: sample time [s], which sets the Nyquist frequency π/dt.
        points: size of the log grid from 0.01 rad/s to Nyquist.

    Returns:
        The −3 dB bandwidth [rad/s]; inf when the gain stays above it below Nyquist.
    """
    level = 10 ** (-3 / 20)
    dc = abs(sys.dcgain())
    omega = np.geomspace(1e-2, np.pi / dt * 0.999, points)
    ratio = np.abs(ct.frequency_response(sys, omega).complex).ravel() / dc
    below = np.nonzero(ratio < level)[0]
    if below.size == 0:
        return float("inf")
    if below[0] == 0:
        return float(omega[0])
    lo, hi = np.log(omega[below[0] - 1]), np.log(omega[below[0]])
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        if abs(sys(np.exp(1j * np.exp(mid) * dt))) / dc < level:
            hi = mid
        else:
            lo = mid
    return float(np.exp(0.5 * (lo + hi)))


def first_crossing(freq: np.ndarray, ratio: np.ndarray, level: float) -> float:
    """Frequency where `ratio` first drops below `level`, log-interpolated; inf if it never does.

    Args:
        freq: frequencies, increasing, shape (k,) (any unit, e.g. [rad/s]).
        ratio: magnitude ratio at each frequency, shape (k,).
        level: threshold ratio (e.g. 10^(−3/20) for −3 dB).

    Returns:
        The first crossing frequency, in the unit of `freq`; freq[0] if already below there.
    """
    below = np.nonzero(ratio < level)[0]
    if below.size == 0:
        return float("inf")
    j = below[0]
    if j == 0:
        return float(freq[0])
    # Interpolate in log-frequency between the last point above and the first below.
    f0, f1, r0, r1 = np.log(freq[j - 1]), np.log(freq[j]), ratio[j - 1], ratio[j]
    return float(np.exp(f0 + (level - r0) * (f1 - f0) / (r1 - r0)))
