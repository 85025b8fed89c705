"""Sweeps: expansion, one folder per config, identical numbers on all backends, resuming."""

from __future__ import annotations

import copy
import itertools
import os
import signal
import subprocess
import time
import tomllib
from pathlib import Path

import pyarrow.parquet as pq
import pytest
import tomli_w

from articula.errors import ConfigError
from articula.experiments import records, runner
from articula.experiments.registry import config_to_dict, parse_config

BASE = {"experiment": "motor.current", "duration": 0.5, "settle": 0.2}
# 2 seeds x 2 filter orders x (constant, sinusoid) = 8 runs, each a few milliseconds.
SPEC = {
    "base": BASE,
    "grid": {"seed": [0, 1], "controller.filter_order": [1, 4]},
    "runs": [{}, {"reference": {"amplitude": 0.1, "frequency": 40.0}}],
}


def _hidden(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.name.startswith(".")]


def _write_spec(path: Path, spec: dict) -> Path:
    path.write_text(tomli_w.dumps(spec))
    return path


@pytest.fixture(scope="module")
def sweep_cli(cli, one_json):
    """sweep_cli(spec, out, *options) runs `articula sweep ... --json`; returns its summary."""

    def run(spec_path: Path, out: Path, *options: str) -> dict:
        proc = cli("sweep", spec_path, "--out", out, *options, "--json")
        assert proc.returncode == 0, proc.stderr
        summary = one_json(proc.stdout)
        assert summary["runs"] == len(runner.expand_sweep(tomllib.loads(spec_path.read_text())))
        assert Path(summary["results"]) == out / runner.RESULTS
        return summary

    return run


def _results(out: Path) -> dict[str, list]:
    """results.parquet without the wall-clock column, as plain lists."""
    table = pq.read_table(out / runner.RESULTS)
    return table.drop_columns(["wall_time_s"]).to_pydict()


def _run_folders(out: Path) -> list[str]:
    return sorted(p.name for p in out.iterdir() if p.is_dir())


def _assert_same_sweep(a: Path, b: Path) -> None:
    """Two sweep folders hold identical configs, metrics and traces (wall times aside)."""
    assert _results(a) == _results(b)
    assert _run_folders(a) == _run_folders(b)
    for name in _run_folders(a):
        assert (a / name / records.CONFIG).read_bytes() == (b / name / records.CONFIG).read_bytes()
        ra, rb = records.read_record(a / name), records.read_record(b / name)
        assert ra["metrics"] == rb["metrics"], name
        assert ra["config_hash"] == rb["config_hash"] == name
        ta = pq.read_table(a / name / records.TRACE)
        tb = pq.read_table(b / name / records.TRACE)
        assert ta.equals(tb), name


# ----- expansion -------------------------------------------------------------------------------


def test_expand_sweep_count_order_and_contents():
    spec = {
        "base": {**BASE, "reference": {"current": 0.5}},
        "grid": {"controller.filter_order": [1, 2, 3], "seed": [0, 1]},
        "runs": [{"reference": {"amplitude": 0.1, "frequency": 25.0}}, {"rig": "single"}],
    }
    configs = runner.expand_sweep(spec)
    assert len(configs) == 3 * 2 * 2
    got = [
        (c["controller"]["filter_order"], c["seed"], c["rig"], c["reference"]["frequency"])
        for c in configs
    ]
    runs = [("dual", 25.0), ("single", 0.0)]
    want = [(k, s, *r) for k, s, r in itertools.product([1, 2, 3], [0, 1], runs)]
    assert got == want  # Cartesian product of the grid, each point with every run, in order
    for c in configs:
        assert c["reference"]["current"] == 0.5  # base survives the deep merge with runs
        assert c["duration"] == 0.5 and c["settle"] == 0.2
        assert c["dt"] == 1e-3  # defaults are filled in
        exp, model = parse_config(c)
        assert config_to_dict(exp, model) == c  # already the full, validated config
    amplitudes = {c["rig"]: c["reference"]["amplitude"] for c in configs}
    assert amplitudes == {"dual": 0.1, "single": 0.0}
    assert len({records.config_hash(c) for c in configs}) == len(configs)


def test_expand_sweep_without_grid_or_runs():
    [alone] = runner.expand_sweep({"base": BASE})
    exp, model = parse_config(BASE)
    assert alone == config_to_dict(exp, model)
    only_runs = runner.expand_sweep({"base": BASE, "runs": [{"seed": 1}, {"seed": 2}, {}]})
    assert [c["seed"] for c in only_runs] == [1, 2, 0]
    only_grid = runner.expand_sweep({"base": BASE, "grid": {"pwm.bits": [0, 8, 12]}})
    assert [c["pwm"]["bits"] for c in only_grid] == [0, 8, 12]
    # The experiment may come from the runs instead of the base.
    no_base = runner.expand_sweep({"runs": [{**BASE, "seed": 3}]})
    assert no_base[0]["seed"] == 3


def test_expand_sweep_of_packaged_bandwidth_sweep():
    from importlib import resources

    path = resources.files("articula.experiments") / "configs" / "ch4" / "bandwidth_quick.toml"
    spec = tomllib.loads(path.read_text())
    configs = runner.expand_sweep(spec)
    assert len(configs) == 5 * 1 * 10
    assert {c["controller"]["filter_order"] for c in configs} == {1, 4, 16, 64, 256}
    assert all(c["reference"]["amplitude"] == 0.1 for c in configs)


@pytest.mark.parametrize(
    ("spec", "field"),
    [
        ({"base": BASE, "grids": {"seed": [0]}}, "grids"),
        ({"base": BASE, "grid": {"seed": 0}}, "grid.seed"),
        ({"base": BASE, "grid": {"seed": []}}, "grid.seed"),
        ({"base": BASE, "grid": {"controller.kd": [1.0]}}, "controller.kd"),
        ({"base": BASE, "grid": {"controler.kp": [1.0]}}, "controler"),
        ({"base": BASE, "grid": {"seed": [0, -1]}}, "seed"),
        ({"base": BASE, "grid": {"controller.filter_order": [1, 0]}}, "controller.filter_order"),
        ({"base": BASE, "grid": {"duration": [1.0, float("nan")]}}, "duration"),
        ({"base": BASE, "grid": {"rig": ["dual", "quad"]}}, "rig"),
        ({"base": {**BASE, "seed": 0}, "grid": {"seed.x": [1]}}, "grid.seed.x"),
        ({"base": BASE, "runs": [{"settle": 9.0}]}, "config"),
        ({"base": {"duration": 1.0}, "grid": {"seed": [0]}}, "experiment"),
    ],
    ids=[
        "unknown_sweep_key",
        "grid_value_not_list",
        "grid_value_empty",
        "unknown_grid_key",
        "misspelt_table",
        "bad_grid_value",
        "filter_order_zero",
        "nan_grid_value",
        "bad_literal",
        "dotted_through_scalar",
        "invalid_run",
        "missing_experiment",
    ],
)
def test_expand_sweep_rejects_bad_grid(spec, field):
    with pytest.raises(ConfigError) as exc:
        runner.expand_sweep(spec)
    assert field in exc.value.field
    assert isinstance(exc.value, ValueError)


@pytest.mark.parametrize(
    "spec",
    [
        {"base": BASE, "grid": {"seed": [0, 0]}},
        {"base": BASE, "grid": {"controller.kp": [10, 10.0]}},
        {"base": BASE, "runs": [{}, {"rig": "dual"}]},  # the default rig is dual
        {"base": BASE, "runs": [{"seed": 1}, {"seed": 2}], "grid": {"seed": [0]}},
    ],
    ids=["repeated_value", "same_after_validation", "same_after_defaults", "grid_overrides_runs"],
)
def test_expand_sweep_rejects_duplicate_points(spec):
    with pytest.raises(ConfigError) as exc:
        runner.expand_sweep(spec)
    assert exc.value.field == "grid"
    assert "same config" in exc.value.problem


def test_expand_sweep_does_not_mutate_its_input():
    spec = {
        "base": BASE,
        "runs": [{"reference": {"amplitude": 0.1}}],
        "grid": {"reference.frequency": [30.0, 40.0]},
    }
    before = copy.deepcopy(spec)
    configs = runner.expand_sweep(spec)
    assert [c["reference"]["frequency"] for c in configs] == [30.0, 40.0]
    assert spec == before


# ----- run_sweep in-process: folders, results table, skipping finished runs -------------------


@pytest.fixture
def small_configs():
    return runner.expand_sweep(
        {"base": {**BASE, "duration": 0.2, "settle": 0.1}, "grid": {"seed": [0, 1, 2]}}
    )


def test_run_sweep_writes_one_folder_per_config_and_results(tmp_path, small_configs):
    out = tmp_path / "sweep"
    calls = []
    table = runner.run_sweep(small_configs, out, progress=lambda d, n: calls.append((d, n)))
    hashes = [records.config_hash(c) for c in small_configs]
    assert _run_folders(out) == sorted(hashes)
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
    assert _hidden(out) == []


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


# ----- backends: the same sweep gives identical numbers ---------------------------------------


@pytest.fixture(scope="module")
def sweep_spec(tmp_path_factory) -> Path:
    return _write_spec(tmp_path_factory.mktemp("spec") / "sweep.toml", SPEC)


@pytest.fixture(scope="module")
def serial_sweep(sweep_cli, sweep_spec, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("serial") / "out"
    sweep_cli(sweep_spec, out, "--workers", "1")
    return out


def test_serial_sweep_layout(serial_sweep):
    configs = runner.expand_sweep(SPEC)
    assert len(configs) == 8
    assert _run_folders(serial_sweep) == sorted(records.config_hash(c) for c in configs)
    results = _results(serial_sweep)
    assert results["run"] == [records.config_hash(c) for c in configs]
    assert results["seed"] == [c["seed"] for c in configs]
    assert results["reference.frequency"] == [c["reference"]["frequency"] for c in configs]
    # Sinusoid runs have an amplitude ratio, constant-reference runs a rise time.
    for freq, ratio, rise in zip(
        results["reference.frequency"],
        results["amplitude_ratio"],
        results["rise_time"],
        strict=True,
    ):
        assert (ratio is None) == (freq == 0.0)
        assert (rise is None) == (freq != 0.0)
    # The seed reaches the sensor noise: the two seeds differ.
    noise = dict(zip(zip(results["seed"], results["controller.filter_order"],
                         results["reference.frequency"], strict=True),
                     results["noise_rms"], strict=True))  # fmt: skip
    assert noise[(0, 1, 0.0)] != noise[(1, 1, 0.0)]
    assert _hidden(serial_sweep) == []


def test_process_pool_gives_identical_numbers(sweep_cli, sweep_spec, serial_sweep, tmp_path):
    out = tmp_path / "pool"
    sweep_cli(sweep_spec, out, "--workers", "2")
    _assert_same_sweep(serial_sweep, out)
    assert _hidden(out) == []


def test_dask_local_gives_identical_numbers(sweep_cli, sweep_spec, serial_sweep, tmp_path):
    out = tmp_path / "dask"
    sweep_cli(sweep_spec, out, "--dask", "local", "--workers", "2")
    _assert_same_sweep(serial_sweep, out)
    assert _hidden(out) == []


def test_dask_existing_scheduler_gives_identical_numbers(
    sweep_cli, sweep_spec, serial_sweep, tmp_path
):
    from distributed import LocalCluster

    with LocalCluster(
        host="127.0.0.1", n_workers=1, processes=True, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        assert address.startswith("tcp://127.0.0.1:")
        out = tmp_path / "remote"
        sweep_cli(sweep_spec, out, "--dask", address)
    _assert_same_sweep(serial_sweep, out)


def test_rerun_of_a_complete_sweep_rewrites_no_run(sweep_cli, sweep_spec, serial_sweep, tmp_path):
    import shutil

    out = tmp_path / "copy"
    shutil.copytree(serial_sweep, out)
    stats = {p: p.stat().st_ino for p in out.rglob("*") if p.is_file() and p.parent != out}
    sweep_cli(sweep_spec, out, "--workers", "2")
    for p, ino in stats.items():
        assert p.stat().st_ino == ino, p
    _assert_same_sweep(serial_sweep, out)


# ----- kill and resume -------------------------------------------------------------------------

SLOW_RUNS = 30
# Each run simulates 5 s with a 4000-sample moving average: ~0.1 s of compute plus its writes.
SLOW_SPEC = {
    "base": {
        "experiment": "motor.current",
        "duration": 5.0,
        "settle": 1.0,
        "controller": {"filter_order": 4000},
    },
    "grid": {"seed": list(range(SLOW_RUNS))},
}


def _finished(out: Path) -> dict[str, Path]:
    if not out.exists():
        return {}
    return {p.parent.name: p.parent for p in out.glob(f"*/{records.RECORD}")}


def _snapshot(folder: Path) -> dict[str, tuple[int, int, bytes]]:
    return {
        p.name: (p.stat().st_ino, p.stat().st_mtime_ns, p.read_bytes())
        for p in folder.iterdir()
        if p.is_file()
    }


def test_killed_sweep_resumes_without_recomputing_finished_runs(
    sweep_cli, articula_script, tmp_path
):
    spec = _write_spec(tmp_path / "slow.toml", SLOW_SPEC)
    out = tmp_path / "out"
    configs = runner.expand_sweep(SLOW_SPEC)
    hashes = [records.config_hash(c) for c in configs]

    proc = subprocess.Popen(
        [articula_script, "sweep", str(spec), "--out", str(out), "--workers", "1", "--json"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    try:
        give_up = time.monotonic() + 600  # a safety net against hanging, not a timing check
        while not _finished(out) and proc.poll() is None and time.monotonic() < give_up:
            time.sleep(0.005)
        assert proc.poll() is None, "the sweep ended before it could be interrupted"
        assert _finished(out), "no run finished"
        os.killpg(proc.pid, signal.SIGKILL)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL

    finished = _finished(out)
    assert 1 <= len(finished) < SLOW_RUNS
    assert set(finished) <= set(hashes)
    assert not (out / runner.RESULTS).exists()
    before = {}
    for name, folder in finished.items():
        assert _hidden(folder) == [], name  # no half-written file in a finished run
        assert sorted(p.name for p in folder.iterdir()) == [
            records.CONFIG,
            records.RECORD,
            records.TRACE,
        ]
        pq.read_table(folder / records.TRACE)  # complete and readable
        before[name] = _snapshot(folder)

    summary = sweep_cli(spec, out, "--workers", "2")
    assert summary["runs"] == SLOW_RUNS

    assert set(_finished(out)) == set(hashes)
    for name, snap in before.items():
        assert _snapshot(out / name) == snap, f"finished run {name} was rewritten"
        assert _hidden(out / name) == []
    results = pq.read_table(out / runner.RESULTS)
    assert results.column("run").to_pylist() == hashes
    assert results.column("seed").to_pylist() == list(range(SLOW_RUNS))

    # A run that was still missing at the kill now holds the numbers of a clean run.
    missing = [i for i, h in enumerate(hashes) if h not in finished]
    i = missing[0]
    fresh = runner.execute(configs[i])
    assert records.read_record(out / hashes[i])["metrics"] == fresh.record["metrics"]
