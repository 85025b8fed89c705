"""experiments/pneunet.py: the pneunet.pid config, its reference and the registered run."""

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.experiments.pneunet import (
    ControllerConfig,
    PneuNetPidConfig,
    reference_deg,
    run_pneunet_pid,
)
from articula.runs.registry import parse_config
from articula.runs.runner import execute

SMALL = {"experiment": "pneunet.pid", "trials": 3, "duration": 2.0}


def test_sinusoid_reference_starts_at_rest_and_spans_the_range():
    config = PneuNetPidConfig()
    t = np.arange(config.steps) * config.plant.pwm_period
    r = reference_deg(config.reference, t)
    assert r[0] == pytest.approx(0.0) and r.max() == pytest.approx(90.0, abs=1e-3)


def test_steps_reference_holds_each_level_for_an_equal_share():
    steps = PneuNetPidConfig(reference={"kind": "steps", "levels_deg": [15.0, 45.0]},
                             duration=2.0)  # fmt: skip
    r = reference_deg(steps.reference, np.arange(steps.steps) / 30.0)
    assert r[:30].tolist() == [15.0] * 30 and r[30:].tolist() == [45.0] * 30


def test_experiment_runs_through_the_runner():
    output = execute(SMALL)
    m = output.record["metrics"]
    assert m["error_q1_deg"] <= m["error_median_deg"] <= m["error_q3_deg"]
    assert set(output.trace) == {"t", "theta_ref_deg", "theta_meas_deg", "theta_deg", "duty"}
    assert output.trace["t"].size == 60


def test_trace_is_trial_zero_and_trials_differ():
    config = parse_config(SMALL)[1]
    batch = run_pneunet_pid(config)
    alone = run_pneunet_pid(config.model_copy(update={"trials": 1}))
    np.testing.assert_array_equal(batch.trace["theta_meas_deg"], alone.trace["theta_meas_deg"])
    assert batch.metrics["error_q1_deg"] < batch.metrics["error_q3_deg"]


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"trials": 0}, "trials"),
        ({"reference": {"offset_deg": 60.0, "amplitude_deg": 45.0}}, "reference.amplitude_deg"),
        ({"reference": {"frequency": -1.0}}, "reference.frequency"),
        ({"controller": {"schedule": "fuzzy", "gains": [[1.0, 1.0, 0.0]]}}, "controller.gains"),
        ({"controller": {"gains": [[1.0, 1.0, 0.0]] * 2}}, "controller.gains"),
        (
            {
                "controller": {
                    "schedule": "fuzzy",
                    "gains": [[1.0, 1.0, 0.0]] * 2,
                    "points_deg": [45.0, 15.0],
                }
            },
            "controller.points_deg",
        ),
        ({"controller": {"gains": [[1.0, -1.0, 0.0]]}}, "controller.gains.0.1"),
        ({"controller": {"gains": [[1.0, 1.0]]}}, "controller.gains.0"),
        ({"settle": 5.0, "duration": 2.0}, "settle"),
        ({"duration": 40_000.0}, "duration"),
        ({"trials": 10_000, "duration": 70.0}, "trials"),
        ({"reference": {"kind": "steps", "levels_deg": [10.0] * 61}}, "duration"),
        ({"plant": {"supply_pressure": 10e3}}, "plant.supply_pressure"),
        ({"plant": {"valve_tau": -0.25}}, "plant.valve_tau"),
        ({"gain": 1.0}, "gain"),
    ],
)
def test_bad_config_names_the_field(change, field):
    with pytest.raises(ConfigError) as exc:
        parse_config({**SMALL, **change})
    assert exc.value.field == field, exc.value


def test_controller_config_builds_the_schedule():
    c = ControllerConfig(schedule="piecewise", gains=[[1, 1, 0], [2, 2, 0], [3, 3, 0]])
    pid = c.build(trials=2)
    assert pid.output_limits == (0.0, 255.0)
    assert pid.schedule(59.0).tolist() == [2.0, 2.0, 0.0]


def test_bad_config_on_the_command_line_is_one_line(
    cli, write_toml, tmp_path, assert_one_line_error
):
    path = write_toml({**SMALL, "controller": {"schedule": "piecewise", "gains": [[1, 1, 0]]}})
    proc = cli("run", path, "--out", tmp_path / "run")
    assert_one_line_error(proc, "controller")
