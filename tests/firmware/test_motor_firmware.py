"""The motor rig's firmware (firmware/src/motor.c) in simavr on the simulated dual-motor rig:
chapter 4's experiments (Figs. 4.5-4.9) over the pseudo-terminal agree with the Python
simulation of the same config.

Why not exactly: the AVR computes in float32, the simulation in float64. The control and
sensor channels agree sample for sample until a rounding difference first moves an ADC code
or a duty by one count (after one to five seconds here); from then on the two runs are two
noise-level realisations of the same loop. The metrics therefore agree to the tolerances
below (the run-to-run spread of the statistics, not the float rounding), taken on the plant's
true current and speed, as the simulation takes them.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from articula.book.study import packaged
from articula.errors import ConfigError
from articula.experiments.motor import CurrentControlConfig, simulate_batch
from articula.experiments.motor_on_rig import firmware_motor, run_on_rig, trace_metrics
from articula.rigs.link import Link
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.validation import load_toml, parse_model

pytestmark = pytest.mark.firmware
FIGURES = ["fig4_5", "fig4_6", "fig4_7", "fig4_8", "fig4_9"]
# metric: (relative, absolute) tolerance
TOLERANCE = {
    "steady_state_error": (0.0, 1e-4),  # [A] a mean of ~1e-4 A; the ADC's step is 26 mA
    "current_rms_error": (0.01, 0.0),
    "noise_rms": (0.02, 0.0),
    "speed_mean": (1e-4, 0.0),
    "saturation_fraction": (0.0, 1e-3),
    "rise_time": (0.0, 1e-3),  # [s] one control period
    "rise_time_feedback": (0.0, 1e-3),
    "amplitude_ratio": (2e-3, 0.0),
    "phase_lag": (0.0, 5e-3),  # [rad]
}


def figure_config(name: str) -> CurrentControlConfig:
    """A packaged figure config (its experiment key dropped)."""
    data = load_toml(packaged("ch4", f"{name}.toml"))
    data.pop("experiment")
    return parse_model(CurrentControlConfig, data, name)


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("figure", FIGURES)
def test_a_figures_run_on_the_firmware_agrees_with_the_simulation(figure, on_plant, tmp_path):
    config = figure_config(figure)
    plant = firmware_motor(config)
    rig = on_plant("motor", plant)
    with Link(rig.path, RigKind.MOTOR) as link:
        recorder = Recorder(tmp_path, {"experiment": "motor.current"},
                            [c.name for c in link.info.channels])  # fmt: skip
        run_on_rig(config, link, recorder)
        assert link.stats.dropped == link.stats.crc_errors == 0
    trace = recorder.columns()
    assert len(trace["t"]) == config.steps  # every 1 ms control period
    channels, metrics = simulate_batch(config, trials=1)
    # Sample for sample until the first one-count difference of a duty (after 93 to 3346
    # periods in these runs).
    differs = (trace["duty1"] != channels["duty1"][0]) | ~np.isclose(trace["v2"], channels["v2"][0])
    first = slice(0, int(np.argmax(differs)) if differs.any() else None)
    assert not differs[:50].any()
    for name in ("i_meas", "i_fb", "omega_meas", "v1"):
        assert np.allclose(trace[name][first], channels[name][0][first], rtol=1e-5, atol=1e-5)
    truth = np.array(plant.trace)
    on_rig = trace_metrics(config, trace["t"], {**trace, "i": truth[:, 0], "omega": truth[:, 1]})
    for key, (rel, abs_) in TOLERANCE.items():
        here, there = float(metrics[key][0]), float(on_rig[key][0])
        if math.isnan(here):
            assert math.isnan(there), key
        else:
            assert there == pytest.approx(here, rel=rel, abs=abs_), key
    # The loop fits its period with room to spare (benchmarks/firmware.py measures it).
    assert 0 < max(rig.step_cycles) < 16_000


def test_a_config_the_firmware_is_not_built_for_is_refused_by_field():
    config = figure_config("fig4_5")
    with pytest.raises(ConfigError, match=r"encoder.counts_per_rev.*firmware/src/motor.c"):
        firmware_motor(config.model_copy(update={"encoder": config.encoder.model_copy(
            update={"counts_per_rev": 500})}))  # fmt: skip


@pytest.mark.slow
def test_emulate_motor_with_firmware_runs_a_figure_from_the_command_line(emulated, cli, tmp_path):
    _, path = emulated("motor")
    config = packaged("ch4", "fig4_8.toml")
    done = cli("rig", "run", path, config, "--out", tmp_path / "run", "--json")
    assert done.returncode == 0, done.stderr
    record = json.loads(done.stdout)
    assert record["complete"] and record["samples"] == figure_config("fig4_8").steps
    here = simulate_batch(figure_config("fig4_8"), trials=1)[1]
    assert record["metrics"]["speed_mean"] == pytest.approx(float(here["speed_mean"][0]),
                                                            rel=1e-3)  # fmt: skip
    # What the sensor alone cannot measure is left out, not given another meaning.
    assert record["metrics"]["current_rms_error"] is None
    assert record["metrics"]["noise_rms"] is None
    table = cli("rig", "run", path, config, "--out", tmp_path / "table").stdout
    row = next(line for line in table.splitlines() if "noise_rms" in line)
    name, on_rig, on_model = (cell.strip() for cell in row.strip("│ ").split("│"))
    assert (name, on_rig) == ("noise_rms", "—") and float(on_model) > 0  # the model has it
