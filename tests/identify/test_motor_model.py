"""The model the motor's fit simulates, against python-control: the single rig's state space
(Eq. 4.6 with the shaft angle), sampled with a zero-order hold by control.sample_system and
driven by the same voltages through control.forced_response, gives the same current and
speed; and the encoder's windowed speed is the angle's difference over the window."""

from __future__ import annotations

import control
import numpy as np

from articula.identify.motor import MotorRecording, simulate
from articula.plants.dc_motor import TABLE_4_1
from articula.plants.motor_rig import I_PRIMARY, OMEGA, THETA, rig_matrices

DT = 1e-3


def _recording() -> MotorRecording:
    """Random voltages held over 2 s (a seeded draw)."""
    v1 = np.random.default_rng(0).uniform(-12, 12, 2000)
    zeros = np.zeros_like(v1)
    return MotorRecording(DT, v1, zeros, zeros)


def test_the_simulated_rig_is_python_controls_zero_order_hold_response():
    recording = _recording()
    A, B = rig_matrices(TABLE_4_1, dual=False)
    discrete = control.sample_system(control.ss(A, B[:, :1], np.eye(3), 0), DT, method="zoh")
    response = control.forced_response(discrete, U=recording.v1)
    states = np.asarray(response.states).T
    current, speed = simulate(TABLE_4_1, recording, window=0)
    np.testing.assert_allclose(current, states[:, I_PRIMARY], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(speed, states[:, OMEGA], rtol=1e-9, atol=1e-9)
    _, windowed = simulate(TABLE_4_1, recording, window=50)
    theta = states[:, THETA]
    expected = (theta[100:] - theta[50:-50]) / (50 * DT)
    np.testing.assert_allclose(windowed[100:], expected, rtol=1e-9, atol=1e-9)
