"""The runner: one config into a run folder, a sweep into run folders and results.parquet."""

from __future__ import annotations

import tomllib

import pyarrow.parquet as pq
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.runs import records, runner, sweep
from tests.helpers import hidden_files, run_folders

BASE = {"experiment": "motor.current", "duration": 0.5, "settle": 0.2}


@pytest.fixture
def small_configs():
    return sweep.expand_sweep(
        {"base": {**BASE, "duration": 0.2, "settle": 0.1}, "grid": {"seed": [0, 1, 2]}}
    )


def test_run_sweep_writes_one_folder_per_config_and_results(tmp_path, small_configs):
    out = tmp_path / "sweep"
    calls = []
    table = runner.run_sweep(small_configs, out, progress=lambda d, n: calls.append((d, n)))
    hashes = [records.config_hash(c) for c in small_configs]
    assert run_folders(out) == sorted(hashes)
    for h, cfg in zip(hashes, small_configs, strict=True):
        assert records.is_finished(out / h)
        assert tomllib.loads((out / h / records.CONFIG).read_text()) == cfg
        assert records.read_record(out / h)["config_hash"] == h
    assert calls == [(0, 3), (1, 3), (2, 3), (3, 3)]
    assert pq.read_table(out / runner.RESULTS).equals(table)
    rows = table.to_pylist()
    assert [r["run"] for r in rows] == hashes  # config order, not completion order
    for row, h in zip(rows, hashes, strict=True):
        record = records.read_record(out / h)
        for metric, value in record["metrics"].items():
            assert row[metric] == value
        assert row["wall_time_s"] == record["wall_time_s"]
    assert [r["seed"] for r in rows] == [0, 1, 2]
    assert {"controller.filter_order", "reference.frequency", "pwm.bits"} <= set(rows[0])
    assert hidden_files(out) == []


def test_run_sweep_skips_finished_runs(tmp_path, small_configs, monkeypatch):
    out = tmp_path / "sweep"
    first = runner.run_sweep(small_configs, out)
    stats = {p: p.stat() for p in out.rglob(records.RECORD)}

    def no_compute(config):
        raise AssertionError("a finished run was recomputed")

    monkeypatch.setattr(runner, "execute", no_compute)
    calls = []
    again = runner.run_sweep(small_configs, out, progress=lambda d, n: calls.append((d, n)))
    assert calls == [(3, 3)]
    assert again.equals(first)
    for p, st in stats.items():
        assert (p.stat().st_ino, p.stat().st_mtime_ns) == (st.st_ino, st.st_mtime_ns)


def test_run_sweep_recomputes_only_unfinished_runs(tmp_path, small_configs, monkeypatch):
    out = tmp_path / "sweep"
    runner.run_sweep(small_configs, out)
    lost = out / records.config_hash(small_configs[1])
    before = records.read_record(lost)["metrics"]
    (lost / records.RECORD).unlink()  # as if killed before the record was written
    kept = {p: p.stat().st_ino for p in out.rglob(records.RECORD)}

    computed = []
    real = runner.execute

    def spy(config):
        computed.append(records.config_hash(config))
        return real(config)

    monkeypatch.setattr(runner, "execute", spy)
    table = runner.run_sweep(small_configs, out)
    assert computed == [lost.name]
    assert records.read_record(lost)["metrics"] == before
    assert table.num_rows == 3
    for p, ino in kept.items():
        assert p.stat().st_ino == ino


def test_results_cover_only_the_configs_of_this_sweep(tmp_path, small_configs):
    out = tmp_path / "sweep"
    runner.run_sweep(small_configs, out)
    table = runner.run_sweep(small_configs[:2], out)
    assert table.column("run").to_pylist() == [records.config_hash(c) for c in small_configs[:2]]
    assert pq.read_table(out / runner.RESULTS).num_rows == 2


def test_run_sweep_rejects_a_bad_dask_address(tmp_path, small_configs):
    with pytest.raises(ConfigError) as exc:
        runner.run_sweep(small_configs, tmp_path / "sweep", dask="localhost:8786")
    assert exc.value.field == "--dask"


def test_run_to_folder_seed_changes_noise_only(tmp_path, tiny_config):
    a = runner.run_to_folder({**tiny_config, "seed": 1}, tmp_path / "a")
    b = runner.run_to_folder({**tiny_config, "seed": 1}, tmp_path / "b")
    c = runner.run_to_folder({**tiny_config, "seed": 2}, tmp_path / "c")
    assert a["metrics"] == b["metrics"]
    assert a["metrics"]["noise_rms"] != c["metrics"]["noise_rms"]
    assert a["config_hash"] != c["config_hash"]
    ideal = runner.run_to_folder({**tiny_config, "sensor": {"ideal": True}}, tmp_path / "d")
    assert ideal["metrics"]["noise_rms"] == 0.0


def test_run_over_an_existing_folder_replaces_it_cleanly(tmp_path, tiny_config):
    out = tmp_path / "run"
    runner.run_to_folder({**tiny_config, "seed": 3}, out)
    record = runner.run_to_folder({**tiny_config, "seed": 4}, out)
    assert records.read_record(out) == record
    assert tomllib.loads((out / "config.toml").read_text())["seed"] == 4
    assert hidden_files(out) == []


def test_sinusoid_run_has_tracking_metrics(tmp_path, tiny_config):
    cfg = {**tiny_config, "duration": 1.0, "settle": 0.5}
    cfg["reference"] = {"amplitude": 0.1, "frequency": 20.0}
    record = runner.run_to_folder(cfg, tmp_path / "sin")
    m = record["metrics"]
    assert m["rise_time"] is None and m["rise_time_feedback"] is None
    assert m["amplitude_ratio"] is not None and m["amplitude_ratio"] > 0
    assert m["phase_lag"] is not None


def test_a_partial_config_names_the_same_run_folder_as_its_complete_form(tmp_path):
    partial = {**BASE, "duration": 0.2, "settle": 0.1}
    [complete] = sweep.expand_sweep({"base": partial})
    assert runner.normalized(partial) == complete
    runner.run_sweep([partial], tmp_path / "a")
    runner.run_sweep([complete], tmp_path / "b")
    assert run_folders(tmp_path / "a") == run_folders(tmp_path / "b")


def test_execute_names_the_file_of_a_bad_config():
    with pytest.raises(ConfigError) as err:
        runner.execute({**BASE, "duration": -1.0}, "bad.toml")
    assert err.value.field == "bad.toml: duration"


def _short_qp_plan() -> dict:
    """A 0.2 s baornn.plan of the qp along a 10 cm segment in front of the iiwa14."""
    return {
        "experiment": "baornn.plan",
        "robot": {"builtin": "iiwa14"},
        "trajectory": {"type": "waypoints", "points": [[0, 0.6, 0.5], [0, 0.6, 0.6]],
                       "times": [0.0, 1.0]},
        "planner": {"method": "qp", "duration": 0.2, "settle": 0.1},
    }  # fmt: skip


def test_an_infeasible_point_is_recorded_and_the_sweep_goes_on(tmp_path):
    plan = _short_qp_plan()
    far = [[3.0, 0.0, 0.5], [3.0, 0.0, 0.6]]  # beyond the arm's reach: refused before planning
    grid = {"trajectory.points": [plan["trajectory"]["points"], far]}
    configs = sweep.expand_sweep({"base": plan, "grid": grid})
    table = runner.run_sweep(configs, tmp_path / "out")
    errors = table.column("error").to_pylist()
    assert errors[0] is None and "reach" in errors[1]
    assert table.column("rms_error").to_pylist()[1] is None
    failed = tmp_path / "out" / records.config_hash(configs[1])
    assert records.is_finished(failed)  # the same config fails the same way: not retried
    assert records.read_record(failed)["error"] == errors[1]


def test_a_point_that_does_not_track_is_a_result_marked_not_tracked(tmp_path):
    plan = _short_qp_plan()
    configs = sweep.expand_sweep({"base": plan, "grid": {"planner.tolerance": [10.0, 1e-9]}})
    table = runner.run_sweep(configs, tmp_path / "out")
    assert table.column("error").to_pylist() == [None, None]
    assert table.column("tracked").to_pylist() == [True, False]
    assert None not in table.column("rms_error").to_pylist()  # measured either way
    record = records.read_record(tmp_path / "out" / records.config_hash(configs[1]))
    assert "planner.tolerance = 1e-09" in record["not_tracked"]


def test_results_spread_short_lists_into_columns():
    flat = runner._flatten({"a": [1.0, 2.0], "b": {"c": [[3, 4]]}, "long": list(range(17))})
    assert flat == {"a.0": 1.0, "a.1": 2.0, "b.c.0.0": 3, "b.c.0.1": 4}


def test_a_run_time_error_names_the_config_file(tmp_path):
    plan = {
        "experiment": "baornn.plan",
        "robot": {"builtin": "iiwa14"},
        "obstacles": [{"sphere": 0.3, "position": [0.0, 0.0, 0.8]}],  # around the home pose
        "trajectory": {"type": "waypoints", "points": [[0, 0.6, 0.5], [0, 0.6, 0.6]],
                       "times": [0.0, 1.0]},
    }  # fmt: skip
    with pytest.raises(InfeasibleError) as err:
        runner.execute(plan, "scene.toml")
    assert err.value.field == "scene.toml: robot.q0"
