"""The six-chamber rig's firmware (firmware/src/six_chamber.c) in simavr on the simulated
actuator: its valve sequence and damping pulse, timed by its 10 kHz tick, and its reading of
the orientation sensor's frames on Serial1 measure what the in-process run senses, and the
damping policy found in simulation damps the emulated rig the same way.

Why not exactly: the pulse's open time comes from the firmware's fill table (linear between
1 % steps of the supply) rather than the model's exact fill time, and the sensor's angles
travel as float32; the runs agree to about 1e-3 of the peak."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from articula.errors import ConfigError, DeviceError
from articula.experiments.six_chamber import DeactuationConfig, run_deactuation
from articula.experiments.six_chamber_on_rig import CHANNELS, run_on_rig
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import SixChamberParams
from articula.rigs.link import Link
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.rigs.six_chamber import SixChamberPins, fill_table_header

pytestmark = pytest.mark.firmware
HEADER = Path(__file__).resolve().parents[2] / "firmware/src/fill_table.h"
PULSE = {"delta": 0.3, "start": 0.15, "length": 0.045}  # brakes the swing after the first


@pytest.fixture(scope="module")
def rig(built):
    """A Link to the six-chamber firmware on the simulated actuator and sensor."""
    from articula.rigs.firmware import FirmwareRig

    with FirmwareRig(built / "six_chamber.elf", SixChamberPins()) as firmware, \
            Link(firmware.path, RigKind.SIX_CHAMBER) as link:  # fmt: skip
        yield link


def both(rig: Link, tmp_path: Path, **damping: float) -> tuple[dict, dict, Recorder]:
    """One run on the firmware and in process: (metrics there, metrics here, its recorder)."""
    config = DeactuationConfig(seed=4, hold=1.0, after=1.5, damping=damping)
    recorder = Recorder(tmp_path, {"experiment": "softarm.damping"}, CHANNELS)
    return run_on_rig(config, rig, recorder), run_deactuation(config).metrics, recorder


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("damping", [{"delta": 0.0}, {"delta": 0.4, "length": 0.1}, PULSE],
                         ids=["undamped", "brief pulse", "timed pulse"])  # fmt: skip
def test_a_run_on_the_firmware_measures_what_the_run_in_process_senses(rig, tmp_path, damping):
    there, here, recorder = both(rig, tmp_path, **damping)
    assert len(recorder.t) == 251  # every 10 ms sensor frame, 0 to 2.5 s
    assert there["peak_deg"] == pytest.approx(here["peak_deg"], rel=1e-3)
    assert there["overshoot_pct"] == pytest.approx(here["overshoot_pct"], rel=2e-3)
    assert there["deactuation_angle_deg"] == pytest.approx(here["deactuation_angle_deg"], rel=1e-3)
    assert there["settling_s"] == pytest.approx(here["settling_s"], abs=0.0101)  # a frame


@pytest.mark.slow
def test_the_policy_found_in_simulation_damps_the_firmware_rig_the_same_way(rig, tmp_path):
    off_there, off_here, _ = both(rig, tmp_path / "off", delta=0.0)
    on_there, on_here, _ = both(rig, tmp_path / "on", **PULSE)
    assert on_here["settling_s"] < 0.3 * off_here["settling_s"]  # 0.97 s -> 0.20 s
    assert on_there["settling_s"] < 0.3 * off_there["settling_s"]
    assert on_there["settling_s"] == pytest.approx(on_here["settling_s"], abs=0.0101)


def test_what_the_firmware_cannot_do_is_refused_by_name(rig, built, tmp_path):
    recorder = Recorder(tmp_path, {"experiment": "softarm.damping"}, CHANNELS)
    with pytest.raises(DeviceError, match="multiple of 60 deg"):
        run_on_rig(DeactuationConfig(side_deg=30.0), rig, recorder)
    late = DeactuationConfig(hold=1.0, after=1.0).model_copy(update={"after": -0.5})
    with pytest.raises(DeviceError, match="ends before the vent"):
        run_on_rig(late, rig, recorder)
    with pytest.raises(ConfigError, match=r"sensor\.rate"):
        SixChamberPins(sensor=OrientationSensorParams(rate=50.0))
    with pytest.raises(ConfigError, match=r"fill_table\.h"):  # its table is another's
        SixChamberPins(SixChamberParams(supply=80e3), firmware=built / "six_chamber.elf")


def test_the_fill_table_in_the_firmware_is_the_models():
    # Regenerate with `python tools/fill_table.py` when the chamber model changes.
    assert HEADER.read_text() == fill_table_header(SixChamberParams())


@pytest.mark.slow
def test_emulate_six_chamber_with_firmware_runs_from_the_command_line(emulated, cli, tmp_path):
    config = tmp_path / "damping.toml"
    config.write_text('experiment = "softarm.damping"\nseed = 4\nhold = 1.0\nafter = 1.0\n'
                      "[damping]\ndelta = 0.3\nstart = 0.15\nlength = 0.045\n")  # fmt: skip
    _, path = emulated("six-chamber")
    done = cli("rig", "run", path, config, "--out", tmp_path / "run", "--json")
    assert done.returncode == 0, done.stderr
    record = json.loads(done.stdout)
    assert record["complete"] and record["samples"] == 201
    assert record["metrics"]["settling_s"] < 0.3
