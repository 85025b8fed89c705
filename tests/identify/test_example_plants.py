"""The hidden plants docs/guides/identify.md emulates ship in examples/plants and load as the
emulated rigs' plants, with the constants the guide states."""

from __future__ import annotations

from pathlib import Path

import pytest

from articula.experiments.rig_registry import rig_named

PLANTS = Path(__file__).resolve().parents[2] / "examples" / "plants"


@pytest.mark.parametrize(
    ("rig", "name", "constant", "value"),
    [
        ("motor", "hidden_motor", "R", 12.15),
        ("pneunet", "hidden_pneunet", "chamber_tau", 0.4),
        ("six-chamber", "hidden_six_chamber", "youngs_modulus", 25000.0),
    ],
)
def test_the_guides_hidden_plants_load_as_emulated_rigs(rig, name, constant, value):
    with rig_named(rig).emulated(PLANTS / f"{name}.toml") as emulator:
        assert Path(emulator.path).exists()
        assert f"{constant} = {value}" in (PLANTS / f"{name}.toml").read_text()
