"""Hidden plants for the identification tests: each constant drawn from 0.5-2× the book's
(Table 4.1; the PneuNet's defaults), written as the plant config `articula emulate RIG
--plant` takes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import tomli_w

from articula.errors import ArticulaError
from articula.identify.pneunet import CONSTANTS as PNEUNET_CONSTANTS
from articula.identify.six_chamber import CONSTANTS as SIX_CHAMBER_CONSTANTS
from articula.plants.dc_motor import TABLE_4_1
from articula.plants.pneunet import PneuNetParams
from articula.plants.six_chamber import SixChamberParams


def hidden_motor(seed: int, folder: Path) -> tuple[dict[str, float], Path]:
    """A motor whose constants are the book's times factors in [0.5, 2] (log-uniform), and its
    single-rig plant config in `folder`."""
    rng = np.random.default_rng(seed)
    motor = {k: v * 2.0 ** rng.uniform(-1, 1) for k, v in TABLE_4_1.model_dump().items()}
    path = folder / f"hidden_{seed}.toml"
    plant = {"rig": "single", "motor": motor, "reference": {"current": 0.3, "speed": 0.0}}
    path.write_text(tomli_w.dumps(plant))
    return motor, path


def assert_identified(found: dict[str, float], hidden: dict[str, float]) -> None:
    """R, K, J, L within 3 % and b within 10 % of the hidden motor's."""
    for name, value in hidden.items():
        tolerance = 0.10 if name == "b" else 0.03
        assert abs(found[name] / value - 1) <= tolerance, (name, found[name], value)


def hidden_pneunet(seed: int, folder: Path) -> tuple[dict[str, float], Path]:
    """A PneuNet whose fitted constants are the defaults times factors in [0.5, 2] (drawn again
    until it bends past 90° at full supply, as a PneuNet must), no trial spread, and its
    pneunet.pid config in `folder`."""
    rng = np.random.default_rng(seed)
    base = PneuNetParams()
    while True:
        drawn = {k: getattr(base, k) * 2.0 ** rng.uniform(-1, 1) for k in PNEUNET_CONSTANTS}
        drawn["damping_ratio"] = min(drawn["damping_ratio"], 0.9)
        try:
            PneuNetParams(**drawn)
            break
        except ArticulaError:
            continue
    path = folder / f"hidden_pneunet_{seed}.toml"
    path.write_text(tomli_w.dumps({"plant": drawn | {"trial_spread": 0.0}}))
    return drawn, path


def assert_within(found: dict[str, float], hidden: dict[str, float], tolerance: float) -> None:
    """Every hidden constant found within `tolerance` (relative)."""
    for name, value in hidden.items():
        assert abs(found[name] / value - 1) <= tolerance, (name, found[name], value)


def hidden_six_chamber(seed: int, folder: Path) -> tuple[dict[str, float], Path]:
    """A six-chamber actuator whose fitted constants are the defaults times factors in
    [0.5, 2], and its softarm.damping config in `folder`."""
    rng = np.random.default_rng(seed)
    base = SixChamberParams()
    drawn = {k: getattr(base, k) * 2.0 ** rng.uniform(-1, 1) for k in SIX_CHAMBER_CONSTANTS}
    path = folder / f"hidden_six_chamber_{seed}.toml"
    path.write_text(tomli_w.dumps({"actuator": drawn}))
    return drawn, path
