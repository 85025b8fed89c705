"""The static and dynamic analysis of Sect. 4.2 for one motor, as one JSON-ready mapping."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from articula.errors import ConfigError, InfeasibleError
from articula.plants.dc_motor import (
    PRESETS,
    MotorParams,
    critical_speed,
    poles,
    state_space,
    steady_state,
    transfer_matrix,
)
from articula.validation import fields_renamed, load_toml, parse_model

MAX_OPERATING = 1e6  # [V, N·m, A]: far beyond any motor, far below an overflow


def load_params(preset: str | None, params_file: Path | None) -> MotorParams:
    """Motor constants from a preset name or a TOML file with keys R, K, b, J, L, at its top
    or in a [motor] table (a motor.current config: `identify motor`'s plant.toml)."""
    if (preset is None) == (params_file is None):
        raise ConfigError("--preset/--params", "give exactly one of --preset or --params")
    if params_file is not None:
        data = load_toml(params_file)
        if isinstance(data.get("motor"), dict):
            with fields_renamed(lambda field: f"{params_file}: motor.{field}"):
                return parse_model(MotorParams, data["motor"])
        return parse_model(MotorParams, data, where=str(params_file))
    if preset not in PRESETS:
        raise ConfigError("--preset", f"unknown preset {preset!r}; choose {', '.join(PRESETS)}")
    return PRESETS[preset]


def analyze(p: MotorParams, voltage: float, torque: float, current: float) -> dict[str, Any]:
    """A, B, poles, G(s), steady state at (V, τ_ex) and ω_c at (V, i) for motor `p`."""
    for name, value in (("--voltage", voltage), ("--torque", torque), ("--current", current)):
        if not abs(value) <= MAX_OPERATING:
            raise ConfigError(
                name, f"must be a finite number within ±{MAX_OPERATING:g} (got {value})"
            )
    A, B = state_space(p)
    omega, i = steady_state(p, voltage, torque)
    eig = poles(p)
    try:
        omega_c: float | None = critical_speed(p, voltage, current)
        omega_c_note = ""
    except InfeasibleError as exc:
        omega_c, omega_c_note = None, str(exc)
    return {
        "params": p.model_dump(),
        "A": A.tolist(),
        "B": B.tolist(),
        "poles": [_complex(z) for z in eig],
        "transfer": {k: {"num": n, "den": d} for k, (n, d) in transfer_matrix(p).items()},
        "steady_state": {"omega": omega, "i": i, "voltage": voltage, "torque": torque},
        "omega_c": omega_c,  # None when --current cannot flow even at standstill
        "omega_c_note": omega_c_note,
    }


def _complex(z: complex) -> float | dict[str, float]:
    """A pole as a float when real, else {"re", "im"}."""
    return float(z.real) if abs(z.imag) < 1e-12 else {"re": float(z.real), "im": float(z.imag)}
