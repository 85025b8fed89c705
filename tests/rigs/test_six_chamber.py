"""The six-chamber rig over a pseudo-terminal: chapter 3's run on the emulated rig measures
what the in-process run measures on its sensor, and the damping policy found in simulation
damps the rig the same way."""

from __future__ import annotations

import pytest

from articula.errors import DeviceError
from articula.experiments.six_chamber import DeactuationConfig, run_deactuation
from articula.experiments.six_chamber_on_rig import CHANNELS, run_on_rig
from articula.rigs.emulator import Emulator
from articula.rigs.link import Link
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.rigs.six_chamber import SixChamberDevice

SENSED = ("peak_deg", "overshoot_pct", "settling_s", "deactuation_angle_deg")


@pytest.fixture(scope="module")
def rig():
    """A Link to an emulated six-chamber rig (the chapter's default actuator and sensor)."""
    emulator = Emulator(SixChamberDevice())
    with emulator, Link(emulator.path, RigKind.SIX_CHAMBER) as link:
        yield link


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("delta", [0.0, 0.4])
def test_a_run_on_the_rig_measures_what_the_run_in_process_senses(rig, tmp_path, delta):
    config = DeactuationConfig(seed=4, hold=1.0, after=1.5,
                               damping={"delta": delta, "length": 0.1})  # fmt: skip
    recorder = Recorder(tmp_path, {"experiment": "softarm.damping"}, CHANNELS)
    on_rig = run_on_rig(config, rig, recorder)
    here = run_deactuation(config).metrics
    for key in SENSED:  # the sensor's readings travel as float32
        assert on_rig[key] == pytest.approx(here[key], rel=1e-5, abs=1e-6), key
    assert len(recorder.t) == 251  # every 10 ms sensor sample, 0 to 2.5 s


def test_the_policy_damps_the_emulated_rig_as_it_damps_the_simulation(rig, tmp_path):
    runs = {}
    for delta in (0.0, 0.4):
        config = DeactuationConfig(seed=4, hold=1.0, after=1.5,
                                   damping={"delta": delta, "length": 0.1})  # fmt: skip
        recorder = Recorder(tmp_path / str(delta), {"experiment": "softarm.damping"}, CHANNELS)
        runs[delta] = (run_on_rig(config, rig, recorder), run_deactuation(config).metrics)
    (rig_off, sim_off), (rig_on, sim_on) = runs[0.0], runs[0.4]
    assert rig_on["peak_deg"] / rig_off["peak_deg"] == pytest.approx(
        sim_on["peak_deg"] / sim_off["peak_deg"], rel=1e-5)  # fmt: skip


def test_a_run_that_ends_before_the_vent_is_refused(rig, tmp_path):
    # Past the config's validation (model_copy): the rig checks what it is sent, too.
    config = DeactuationConfig(hold=1.0, after=1.0).model_copy(update={"after": -0.5})
    recorder = Recorder(tmp_path, {"experiment": "softarm.damping"}, CHANNELS)
    with pytest.raises(DeviceError, match="ends before the vent"):
        run_on_rig(config, rig, recorder)
