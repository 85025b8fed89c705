"""Chapter 2: experiment config, tuning procedures and `articula reproduce ch2` end to end."""

import re
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.experiments import records, runner
from articula.experiments.ch2 import (
    ControllerConfig,
    PneuNetPidConfig,
    SimulatedRig,
    reference_deg,
    run_pneunet_pid,
)
from articula.experiments.ch2_report import (
    CONTROLLERS,
    FREQUENCIES,
    KdVerdict,
    decide_claims,
    kd_verdict,
    kd_zero_status,
)
from articula.experiments.ch2_tuning import KdProbe, step_reference
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
    assert any(t.gains[2] > 0 for t in result.trials)  # K_d > 0 always tried


def _fake(shape):
    """An Experiment whose 10 s step response to 90° is shape(t, gains), with call count."""
    t = np.arange(0, 10, 0.01)
    calls = []

    def experiment(gains):
        calls.append(np.array(gains))
        return Response(t, np.full_like(t, 90.0), shape(t, gains))

    return experiment, calls


def test_manual_procedure_lets_k_d_lower_the_overshoot():
    # Overshoot 90·e^-1·(2s − 1), s = 1 − 20·K_d: 33° at K_d = 0, then 19.9°, 6.6° and 0° at
    # K_d = 0.01, 0.02, 0.04; at 0.08 nothing is left to lower, so K_d = 0.04 is kept.
    def shape(t, k):
        s = max(0.0, 1 - 20 * k[2])
        return 90.0 * (1 - np.exp(-2 * t) * (s * np.cos(2 * np.pi * t) + 1 - s))

    experiment, calls = _fake(shape)
    result = manual_tuning(experiment)
    assert result.gains.tolist() == [0.25, 0.0, 0.04]  # converging at the first K_p
    assert [t.gains[2] for t in result.trials] == [0.0, 0.01, 0.02, 0.04, 0.08]
    assert len(calls) == len(result.trials) and result.within_tolerance
    assert (
        "K_i = 0" in result.trials[0].decision and "keep K_d = 0.04" in result.trials[-1].decision
    )


def test_manual_procedure_tries_k_d_even_without_overshoot_and_never_reruns():
    # First order, no overshoot, a 5° offset that no K_i removes: the K_p ladder runs to its
    # top, every K_i rung fails (recorded, not hidden), one K_d > 0 is tried and rejected.
    experiment, calls = _fake(lambda t, k: 85.0 * (1 - np.exp(-3 * t)))
    result = manual_tuning(experiment)
    gains = [tuple(t.gains) for t in result.trials]
    assert len(set(gains)) == len(gains) == len(calls)  # no experiment run twice
    assert not result.within_tolerance
    assert "top of the ladder with the error above tolerance" in result.trials[-2].decision
    assert result.trials[-1].gains[2] == 0.01 and result.gains[2] == 0.0
    assert (
        result.gains[0]
        == max(t.gains[0] for t in result.trials)
        == Ladder(0.25, 1.5, 40.0).values()[-1]
    )


def test_manual_procedure_refuses_a_first_k_p_that_already_swings():
    experiment, calls = _fake(lambda t, k: 90.0 * (1 - np.cos(2 * np.pi * t)))
    with pytest.raises(InfeasibleError, match=r"kp\.start"):
        manual_tuning(experiment)
    assert len(calls) == 1


def test_ultimate_gain_without_sustained_swings_is_infeasible():
    experiment, _ = _fake(lambda t, k: 90.0 * (1 - np.exp(-3 * t)))
    with pytest.raises(InfeasibleError, match="raise the ladder's stop"):
        ultimate_gain(experiment, Ladder(0.5, 2.0, 4.0), band=2.0)


def test_tuning_records_are_read_only():
    result = manual_tuning(_rig(45.0, 4.0))
    for array in (result.gains, result.trials[0].gains, result.trials[0].response.measured):
        with pytest.raises(ValueError):
            array[0] = 1.0


def test_step_reference_reuses_the_steps_reference():
    r = step_reference((15.0, 45.0), hold=1.0, period=1 / 30)
    assert r.tolist() == [15.0] * 30 + [45.0] * 30


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
        runner.parse_config({**SMALL, **change})
    assert exc.value.field == field, exc.value


def test_controller_config_builds_the_schedule():
    c = ControllerConfig(schedule="piecewise", gains=[[1, 1, 0], [2, 2, 0], [3, 3, 0]])
    pid = c.build(trials=2)
    assert pid.output_limits == (0.0, 255.0)
    assert pid.schedule(59.0).tolist() == [2.0, 2.0, 0.0]


# ----- claims decided by the numbers ------------------------------------------------------------


def _probe(*rows, sustained=None):
    cost = np.array(rows, dtype=float)
    swings = np.zeros_like(cost)
    lasting = np.zeros(cost.shape, dtype=bool) if sustained is None else np.array(sustained)
    return KdProbe(tuple(0.1 * j for j in range(len(rows))), cost, swings, lasting)


NOISE = np.array([0.3, -0.2, 0.1, -0.4, 0.2, 0.0, -0.1, 0.3])


def test_kd_verdicts_on_made_up_probes():
    base = 20.0 + NOISE
    lower = kd_verdict(_probe(base, base - 1.0 + 0.01 * NOISE))
    assert lower.better == (0.1,) and lower.worse == () and lower.lowest == 0.1
    higher = kd_verdict(_probe(base, base + 1.0 + 0.01 * NOISE))
    assert higher.better == () and higher.worse == (0.1,) and higher.lowest == 0.0
    # Slightly lower mean but within the noise of the paired differences: neither.
    noisy = kd_verdict(_probe(base, 20.0 - 0.02 + NOISE[::-1]))
    assert noisy.better == () and noisy.worse == () and noisy.lowest == 0.1
    # Same M, but the K_d > 0 experiments swing without dying out: worse.
    swinging = kd_verdict(_probe(base, base, sustained=[[False] * 8, [True] * 8]))
    assert swinging.worse == (0.1,)
    with pytest.raises(ConfigError):
        kd_verdict(KdProbe((0.1, 0.2), np.ones((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))))


def test_kd_zero_claim_needs_every_set_clearly_against_k_d():
    worse, neither = KdVerdict((), (0.2,), 0.0), KdVerdict((), (), 0.1)
    better = KdVerdict((0.05,), (0.2,), 0.05)
    assert kd_zero_status({"a": worse, "b": worse}) == "reproduced"
    assert kd_zero_status({"a": worse, "b": neither}) == "inconclusive"
    assert kd_zero_status({"a": worse, "b": better}) == "not reproduced"
    with pytest.raises(ConfigError):
        kd_zero_status({})


def _table(medians):
    """A made-up Table 2.3: name -> medians per frequency, quartiles ±1."""
    return {n: {f: (m, m - 1, m + 1) for f, m in zip(FREQUENCIES, medians[n], strict=True)}
            for n in CONTROLLERS}  # fmt: skip


def test_claims_come_out_true_on_a_table_that_shows_them():
    grow = np.arange(len(FREQUENCIES), dtype=float) * 5 + 10
    offset = {"ordinary-manual": 6, "piecewise-manual": 4, "fuzzy-manual": 4,
              "ordinary-auto": 3, "piecewise-auto": 1, "fuzzy-auto": 1}  # fmt: skip
    claims, lines = decide_claims(_table({n: grow + offset[n] for n in CONTROLLERS}),
                                  "reproduced")  # fmt: skip
    assert claims == dict.fromkeys(claims, True) and len(claims) == 4
    assert "21 of 21" in "\n".join(lines) and "28 of 28" in "\n".join(lines)


def test_claims_come_out_false_on_a_table_that_contradicts_them():
    fall = 50 - np.arange(len(FREQUENCIES), dtype=float) * 5
    offset = {"ordinary-manual": 1, "piecewise-manual": 4, "fuzzy-manual": 4,
              "ordinary-auto": 3, "piecewise-auto": 6, "fuzzy-auto": 6}  # fmt: skip
    table = _table({n: fall + offset[n] for n in CONTROLLERS})
    for status in ("not reproduced", "inconclusive"):
        claims, lines = decide_claims(table, status)
        assert not any(claims.values()), claims
    assert "inconclusive" in "\n".join(lines)
    with pytest.raises(ConfigError):
        decide_claims(table, "maybe")


def test_claims_need_more_than_half_and_ties_do_not_count():
    flat = np.full(len(FREQUENCIES), 20.0)
    claims, _ = decide_claims(_table(dict.fromkeys(CONTROLLERS, flat)), "reproduced")
    assert claims["automatic_beats_manual"] is False  # all ties
    assert claims["piecewise_fuzzy_beat_ordinary"] is False
    assert claims["error_grows_with_frequency"] is False  # flat: no growth
    # Scheduled controllers win exactly 14 of 28 (manual all, auto none): not more than half.
    med = dict.fromkeys(CONTROLLERS, flat)
    med = {**med, "ordinary-manual": flat + 1, "ordinary-auto": flat - 1}
    assert decide_claims(_table(med), "reproduced")[0]["piecewise_fuzzy_beat_ordinary"] is False
    med["ordinary-auto"] = flat.copy()
    med["ordinary-auto"][0] += 1  # one more win: 15 of 28
    assert decide_claims(_table(med), "reproduced")[0]["piecewise_fuzzy_beat_ordinary"] is True


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
