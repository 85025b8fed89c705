"""Hidden motors for the identification tests: each constant drawn from 0.5-2× the book's
(Table 4.1), written as the plant config `articula emulate motor --plant` takes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import tomli_w

from articula.plants.dc_motor import TABLE_4_1


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
