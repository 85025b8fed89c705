"""Chapter 2: experiment config, tuning procedures and `articula reproduce ch2` end to end."""

import re
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from articula.errors import ConfigError
from articula.experiments import records, runner
from articula.experiments.ch2 import (
    ControllerConfig,
    PneuNetPidConfig,
    SimulatedRig,
    reference_deg,
    run_pneunet_pid,
)
from articula.experiments.ch2_report import CONTROLLERS, FREQUENCIES
from articula.plants.pneunet import PneuNetParams
from articula.tuning.manual import Ladder, manual_tuning, ultimate_gain, ziegler_nichols
from articula.tuning.response import Response, step_features, tracking_error, tuning_cost
from articula.validation import load_toml

FIGURES = ["fig2_5", "fig2_6", "fig2_7", "fig2_8", "fig2_9", "fig2_10"]
SMALL = {"experiment": "pneunet.pid", "trials": 3, "duration": 2.0}


# ----- metrics and step-response features ------------------------------------------------------


def test_tracking_error_and_tuning_cost_by_hand():
    t = np.array([0.0, 0.5, 1.0])
    ref = np.array([1.0, 1.0, 1.0])
    y = np.array([0.0, 0.5, 2.0])
    assert tracking_error(ref, y) == pytest.approx((1 + 0.5 + 1) / 3)  # Eq. (2.7)
    # e = 1, 0.5, -1; Δe/Δt = 0 (first sample), -1, -3: M = (1 + 1.5 + 4) / 3, Eq. (2.5)
    assert tuning_cost(t, ref, y) == pytest.approx(6.5 / 3)


def test_step_features_of_a_damped_cosine():
    # y = 1 - exp(-t) cos(2πt): extremes where tan(2πt) = -1/(2π), every 0.5 s from
    # t1 = 0.5 - atan(1/(2π))/(2π), each smaller by exp(-0.5).
    t = np.arange(0, 8, 1e-3)
    y = 1 - np.exp(-t) * np.cos(2 * np.pi * t)
    f = step_features(Response(t, np.ones_like(t), y), band=0.01)
    t1 = 0.5 - np.arctan(1 / (2 * np.pi)) / (2 * np.pi)
    assert f.overshoot == pytest.approx(-np.exp(-t1) * np.cos(2 * np.pi * t1), rel=1e-5)
    assert f.peak_times[:3] == pytest.approx([t1, t1 + 0.5, t1 + 1.0], abs=1e-3)
    assert f.peak_sizes[1] / f.peak_sizes[0] == pytest.approx(np.exp(-0.5), rel=1e-2)
    assert f.converging and f.period == pytest.approx(1.0, abs=1e-2)
    assert f.steady_state_error < 1e-3


def test_step_features_without_oscillation():
    t = np.arange(0, 5, 0.01)
    f = step_features(Response(t, np.full_like(t, 2.0), 1.5 * (1 - np.exp(-3 * t))), band=0.01)
    assert not f.oscillates and np.isnan(f.decay) and f.overshoot == 0.0
    assert f.steady_state_error == pytest.approx(0.5, abs=1e-3)


def test_ziegler_nichols_table():
    assert ziegler_nichols(10.0, 2.0, "PID") == pytest.approx([6.0, 6.0, 1.5])
    assert ziegler_nichols(10.0, 2.0, "PI") == pytest.approx([4.5, 2.7, 0.0])
    assert ziegler_nichols(10.0, 2.0, "P") == pytest.approx([5.0, 0.0, 0.0])
    with pytest.raises(ConfigError) as exc:
        ziegler_nichols(10.0, 2.0, "PD")
    assert exc.value.field == "rule"
    with pytest.raises(ConfigError):
        ziegler_nichols(-1.0, 2.0)


def test_ladder_values_and_bad_ladder():
    assert Ladder(1.0, 2.0, 8.0).values() == [1.0, 2.0, 4.0, 8.0]
    with pytest.raises(ConfigError):
        Ladder(1.0, 0.5, 8.0)


# ----- tuning on the simulated rig ------------------------------------------------------------


def _rig(level: float, seconds: float, seed: int = 0) -> SimulatedRig:
    return SimulatedRig(PneuNetParams(), np.full(round(seconds * 30), level), seed)


def test_rig_runs_one_fresh_experiment_per_call():
    rig = _rig(45.0, 2.0)
    a, b = rig(np.array([1.0, 2.0, 0.0])), rig(np.array([1.0, 2.0, 0.0]))
    assert rig.calls == 2 and not np.array_equal(a.measured, b.measured)
    again = _rig(45.0, 2.0)(np.array([1.0, 2.0, 0.0]))
    np.testing.assert_array_equal(a.measured, again.measured)


def test_manual_procedure_follows_its_own_rules():
    result = manual_tuning(_rig(75.0, 10.0))
    kp, ki, kd = result.gains
    p_only = [t for t in result.trials if t.gains[1] == 0 and t.gains[2] == 0]
    # K_p: every smaller rung showed no oscillation; the chosen one converges (or the next grew).
    chosen = next(t for t in p_only if t.gains[0] == kp)
    assert chosen.features.converging or any(t.gains[0] > kp for t in p_only)
    assert all(not t.features.oscillates for t in p_only if t.gains[0] < kp)
    # K_i: the final response has its steady-state error within tolerance (1°).
    final = [t for t in result.trials if np.array_equal(t.gains, result.gains)][-1]
    assert final.features.steady_state_error <= 1.0 and ki > 0
    assert kd >= 0 and all(t.decision for t in result.trials)


def test_ultimate_gain_finds_a_sustained_oscillation():
    ku, tu, trials = ultimate_gain(_rig(90.0, 10.0), Ladder(0.5, 1.5, 100.0), band=2.0)
    assert trials[-1].decision == "sustained" and trials[-1].gains[0] == ku
    assert 0.1 < tu < 2.0


# ----- the registered experiment ---------------------------------------------------------------


def test_reference_starts_at_rest_and_spans_the_range():
    config = PneuNetPidConfig()
    t = np.arange(config.steps) * config.plant.pwm_period
    r = reference_deg(config.reference, t)
    assert r[0] == pytest.approx(0.0) and r.max() == pytest.approx(90.0, abs=1e-3)
    steps = PneuNetPidConfig(reference={"kind": "steps", "levels_deg": [15.0, 45.0]},
                             duration=2.0)  # fmt: skip
    r = reference_deg(steps.reference, np.arange(steps.steps) / 30.0)
    assert r[:30].tolist() == [15.0] * 30 and r[30:].tolist() == [45.0] * 30


def test_experiment_runs_through_the_runner():
    output = runner.execute(SMALL)
    m = output.record["metrics"]
    assert m["error_q1_deg"] <= m["error_median_deg"] <= m["error_q3_deg"]
    assert set(output.trace) == {"t", "theta_ref_deg", "theta_meas_deg", "theta_deg", "duty"}
    assert output.trace["t"].size == 60


def test_trace_is_trial_zero_and_trials_differ():
    config = runner.parse_config(SMALL)[1]
    batch = run_pneunet_pid(config)
    alone = run_pneunet_pid(config.model_copy(update={"trials": 1}))
    np.testing.assert_array_equal(batch.trace["theta_meas_deg"], alone.trace["theta_meas_deg"])
    assert batch.metrics["error_q1_deg"] < batch.metrics["error_q3_deg"]


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"trials": 0}, "trials"),
        ({"reference": {"offset_deg": 60.0, "amplitude_deg": 45.0}}, "reference"),
        ({"reference": {"frequency": -1.0}}, "reference.frequency"),
        ({"controller": {"schedule": "fuzzy", "gains": [[1.0, 1.0, 0.0]]}}, "controller"),
        ({"controller": {"gains": [[1.0, -1.0, 0.0]]}}, "controller.gains"),
        ({"controller": {"gains": [[1.0, 1.0]]}}, "controller.gains"),
        ({"settle": 5.0, "duration": 2.0}, "config"),
        ({"plant": {"valve_tau": 0.25}}, "plant"),
        ({"gain": 1.0}, "gain"),
    ],
)
def test_bad_config_names_the_field(change, field):
    with pytest.raises(ConfigError) as exc:
        runner.parse_config({**SMALL, **change})
    assert exc.value.field.startswith(field), exc.value


def test_controller_config_builds_the_schedule():
    c = ControllerConfig(schedule="piecewise", gains=[[1, 1, 0], [2, 2, 0], [3, 3, 0]])
    pid = c.build(trials=2)
    assert pid.output_limits == (0.0, 255.0)
    assert pid.schedule(59.0).tolist() == [2.0, 2.0, 0.0]


# ----- `articula reproduce ch2` --------------------------------------------------------------


@pytest.fixture(scope="module")
def ch2(cli, one_json, tmp_path_factory):
    """`articula reproduce ch2 --out DIR --json` (quick mode), run once for the module."""
    out = tmp_path_factory.mktemp("reproduce") / "report"
    proc = cli("reproduce", "ch2", "--out", out, "--json", "--workers", "2")
    assert proc.returncode == 0, proc.stderr
    return out, one_json(proc.stdout)


def test_json_has_the_tables_and_claims(ch2):
    _, summary = ch2
    data = summary["chapters"]["ch2"]
    assert sorted(data["table_2_3"]) == sorted(CONTROLLERS)
    for rows in data["table_2_3"].values():
        assert list(rows) == [f"{f:g}" for f in FREQUENCIES]
        for median, q1, q3 in rows.values():
            assert 0 <= q1 <= median <= q3 <= 90
    assert sorted(data["table_2_2"]) == ["auto", "manual"]
    assert sorted(data["table_2_2"]["auto"]) == ["15", "45", "75", "sequence"]
    for gains in data["table_2_2"]["manual"].values():
        assert set(gains) == {"kp", "ki", "kd"} and min(gains.values()) >= 0
    assert set(data["claims"]) == {
        "automatic_beats_manual", "piecewise_fuzzy_beat_ordinary",
        "error_grows_with_frequency", "kd_zero_optimal",
    }  # fmt: skip
    assert all(isinstance(v, bool) for v in data["claims"].values())


def test_report_section_figures_and_sweep(ch2):
    out, _ = ch2
    text = (out / "report.md").read_text()
    assert "## Chapter 2: PID control of a soft bending actuator (PneuNet)" in text
    assert "19.03" in text and "45.14" in text  # the book's Table 2.3 beside ours
    assert not re.search(r"\b(nan|inf)\b", text, flags=re.IGNORECASE)
    assert len(re.findall(r"\*\*(Reproduced|Not reproduced)\.\*\*", text)) == 4
    for name in FIGURES:
        assert (out / "ch2" / f"{name}.png").read_bytes()[:4] == b"\x89PNG"
    links = re.findall(r"!\[[^\]]*\]\((ch2/[^)]+)\)", text)
    assert sorted(Path(link).stem for link in links) == sorted(FIGURES)
    sweep = out / "ch2" / "table2_3_sweep"
    assert pq.read_table(sweep / runner.RESULTS).num_rows == len(CONTROLLERS) * len(FREQUENCIES)
    # The sweep file beside the report runs again through `articula sweep` with nothing to do.
    configs = runner.expand_sweep(load_toml(out / "ch2" / "table2_3_sweep.toml"))
    assert all(records.is_finished(sweep / records.config_hash(c)) for c in configs)


def test_bad_config_on_the_command_line_is_one_line(
    cli, write_toml, tmp_path, assert_one_line_error
):
    path = write_toml({**SMALL, "controller": {"schedule": "piecewise", "gains": [[1, 1, 0]]}})
    proc = cli("run", path, "--out", tmp_path / "run")
    assert_one_line_error(proc, "controller")
