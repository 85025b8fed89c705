"""The dual-motor rig over a pseudo-terminal: the experiments of Figs. 4.5-4.9 on the
emulated rig give chapter 4's in-process metrics (the same seeds; float32 on the line)."""

from __future__ import annotations

import math

import pytest

from articula.book.study import packaged
from articula.errors import DeviceError
from articula.experiments.motor import CurrentControlConfig, run_current_control
from articula.experiments.motor_on_rig import DEVICE_CHANNELS, emulated_motor, run_on_rig
from articula.rigs.emulator import Emulator
from articula.rigs.link import Link
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.validation import load_toml, parse_model


def figure_config(name: str) -> CurrentControlConfig:
    """A packaged figure config (its experiment key dropped)."""
    data = load_toml(packaged("ch4", f"{name}.toml"))
    data.pop("experiment")
    return parse_model(CurrentControlConfig, data, name)


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("figure", ["fig4_5", "fig4_6", "fig4_7", "fig4_8", "fig4_9"])
def test_a_figures_run_on_the_emulated_rig_has_the_in_process_metrics(figure, tmp_path):
    config = figure_config(figure)
    emulator = Emulator(emulated_motor(config))
    with emulator, Link(emulator.path, RigKind.MOTOR) as link:
        recorder = Recorder(tmp_path, {"experiment": "motor.current"}, DEVICE_CHANNELS)
        on_rig = run_on_rig(config, link, recorder)
        assert link.stats.dropped == link.stats.crc_errors == 0
    here = run_current_control(config).metrics
    assert set(on_rig) == set(here)
    for key, value in here.items():
        if math.isnan(value):
            assert math.isnan(on_rig[key]), key
        else:  # currents, voltages and speeds travel as float32 (7 digits)
            assert on_rig[key] == pytest.approx(value, rel=1e-5, abs=1e-6), key
    assert len(recorder.t) == config.steps  # every 1 ms control period


def test_bad_motor_gains_are_refused_by_the_rig(tmp_path):
    config = figure_config("fig4_5")
    bad = config.model_copy(update={"controller": config.controller.model_copy(
        update={"kp": -1.0})})  # fmt: skip
    emulator = Emulator(emulated_motor(config))
    with emulator, Link(emulator.path) as link, pytest.raises(DeviceError, match="gains"):
        run_on_rig(bad, link, Recorder(tmp_path, {"experiment": "motor.current"}, DEVICE_CHANNELS))
