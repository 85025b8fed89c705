"""Hypothesis strategies shared by the motor tests."""

from __future__ import annotations

from hypothesis import strategies as st

from articula.plants.dc_motor import MotorParams


@st.composite
def motor_params(draw: st.DrawFn) -> MotorParams:
    """Physically sensible small-to-medium DC motors."""
    return MotorParams(
        R=draw(st.floats(0.5, 50.0)),
        K=draw(st.floats(0.01, 1.0)),
        b=draw(st.one_of(st.just(0.0), st.floats(1e-5, 0.05))),
        J=draw(st.floats(1e-4, 0.5)),
        L=draw(st.floats(1e-4, 0.05)),
    )
