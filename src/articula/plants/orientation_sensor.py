"""Orientation sensor glued to the top surface (Sect. 3.3): roll, pitch, yaw at a sample rate."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field
from scipy.spatial.transform import Rotation

from articula.validation import NonNegative, StrictModel


class OrientationSensorParams(StrictModel):
    """Sample rate [Hz] and Gaussian noise σ [deg] per Euler angle; `ideal` reads the truth.

    The book gives neither; 100 Hz and 0.1° are typical of a fused 9-axis IMU (e.g. BNO055).
    Degrees at this interface, as the book reports angles in degrees.

    Attributes:
        ideal: read the true orientation at every simulation sample (no resampling, no noise).
        rate: sample rate [Hz].
        noise_deg: standard deviation of the Gaussian noise on each Euler angle [deg].
    """

    ideal: bool = False
    rate: Annotated[float, Field(gt=0, le=10_000, allow_inf_nan=False)] = 100.0
    noise_deg: NonNegative = 0.1


def euler_from_bend(beta: np.ndarray) -> np.ndarray:
    """(n, 3) roll, pitch, yaw [rad] (intrinsic Z-Y-X) of the top for bending vectors β (n, 2).

    Args:
        beta: bending vectors β, shape (n, 2) or (2,) [rad].

    Returns:
        Roll, pitch, yaw of the top surface, shape (n, 3) [rad].
    """
    beta = np.atleast_2d(beta)
    rotvec = np.column_stack([-beta[:, 1], beta[:, 0], np.zeros(len(beta))])  # axis ẑ × β̂
    yaw_pitch_roll = Rotation.from_rotvec(rotvec).as_euler("ZYX")
    return yaw_pitch_roll[:, ::-1]


def bend_from_euler(roll_pitch_yaw: np.ndarray) -> np.ndarray:
    """Bending vectors β (n, 2) [rad] from the top's roll, pitch, yaw [rad]: tilt of its normal.

    Args:
        roll_pitch_yaw: roll, pitch, yaw (intrinsic Z-Y-X), shape (n, 3) or (3,) [rad].

    Returns:
        Bending vectors β, shape (n, 2) [rad]; yaw about the normal does not count.
    """
    rpy = np.atleast_2d(roll_pitch_yaw)
    normal = Rotation.from_euler("ZYX", rpy[:, ::-1]).apply([0.0, 0.0, 1.0])
    horizontal = np.hypot(normal[:, 0], normal[:, 1])
    tilt = np.arctan2(horizontal, normal[:, 2])
    scale = np.divide(tilt, horizontal, out=np.ones_like(tilt), where=horizontal > 0)
    return normal[:, :2] * scale[:, None]


def read(
    params: OrientationSensorParams, t: np.ndarray, beta: np.ndarray, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """(sample times [s], roll/pitch/yaw (n, 3) [rad]) of the sensor over a simulated β(t).

    Args:
        params: the sensor's rate, noise and `ideal` switch.
        t: simulation times, shape (k,) [s].
        beta: simulated bending vectors at `t`, shape (k, 2) [rad].
        rng: random generator of the sensor noise.

    Returns:
        ts: sample times, shape (n,) [s] (`t` itself when ideal).
        rpy: measured roll, pitch, yaw, shape (n, 3) [rad].
    """
    if params.ideal:
        return t, euler_from_bend(beta)
    ts = np.arange(t[0], t[-1] + 1e-12, 1.0 / params.rate)
    sampled = np.column_stack([np.interp(ts, t, beta[:, k]) for k in range(2)])
    noise = np.radians(params.noise_deg) * rng.standard_normal((ts.size, 3))
    return ts, euler_from_bend(sampled) + noise
