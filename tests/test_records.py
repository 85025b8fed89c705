"""Run folders: `articula run`, record contents, round trip of config.toml, atomic writes."""

from __future__ import annotations

import json
import math
import os
import tomllib
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from articula.experiments import records, runner
from articula.experiments.registry import Result

RECORD_KEYS = {"experiment", "seed", "config_hash", "metrics", "versions", "wall_time_s"}
METRICS = {
    "steady_state_error",
    "current_rms_error",
    "noise_rms",
    "speed_mean",
    "saturation_fraction",
    "amplitude_ratio",
    "phase_lag",
    "rise_time",
    "rise_time_feedback",
}


def _hidden(folder: Path) -> list[Path]:
    """Every file or folder below `folder` whose name starts with '.' (temporary files)."""
    return [p for p in folder.rglob("*") if p.name.startswith(".")]


def _trace(folder: Path):
    return pq.read_table(folder / records.TRACE)


# ----- articula run --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def run_dir(cli, one_json, tmp_path_factory):
    """`articula run` of a tiny config with --json; returns (out folder, printed record)."""
    base = tmp_path_factory.mktemp("run")
    config = base / "tiny.toml"
    config.write_text('experiment = "motor.current"\nduration = 0.2\nsettle = 0.1\n')
    out = base / "run"
    proc = cli("run", config, "--out", out, "--json")
    assert proc.returncode == 0, proc.stderr
    return out, one_json(proc.stdout)


def test_run_writes_config_record_and_trace(run_dir):
    out, printed = run_dir
    assert sorted(p.name for p in out.iterdir()) == ["config.toml", "record.json", "trace.parquet"]
    assert records.is_finished(out)
    record = json.loads((out / "record.json").read_text())
    assert set(record) >= RECORD_KEYS
    assert record == printed  # --json prints the record that was written
    assert record["experiment"] == "motor.current"
    assert record["seed"] == 0
    assert set(record["metrics"]) == METRICS
    for name, value in record["metrics"].items():
        assert value is None or math.isfinite(value), name
    # A constant reference: no sinusoid metrics, but a rise time.
    assert record["metrics"]["amplitude_ratio"] is None
    assert record["metrics"]["rise_time"] is not None
    assert isinstance(record["wall_time_s"], float) and record["wall_time_s"] >= 0
    versions = record["versions"]
    assert {"python", "articula", "numpy", "scipy", "numba", "pyarrow", "pydantic"} <= set(versions)
    assert versions["articula"] == "0.1.0"


def test_run_config_is_complete_and_hash_matches(run_dir):
    out, record = run_dir
    config = tomllib.loads((out / "config.toml").read_text())
    # Defaults are filled in, so the file alone reproduces the run.
    assert config["experiment"] == "motor.current"
    assert config["duration"] == 0.2 and config["settle"] == 0.1
    for key in ("seed", "rig", "preset", "dt", "reference", "controller", "pwm", "sensor"):
        assert key in config, key
    assert records.config_hash(config) == record["config_hash"]


def test_run_trace_is_a_time_series(run_dir):
    out, _ = run_dir
    table = _trace(out)
    names = table.column_names
    assert names[0] == "t"
    assert {"t", "i", "i_ref", "i_fb", "omega", "v1"} <= set(names)
    assert table.num_rows == 200  # 0.2 s at dt = 1 ms
    t = table["t"].to_numpy()
    np.testing.assert_allclose(np.diff(t), 1e-3, rtol=1e-9)
    assert t[0] == 0.0
    for name in names:
        assert np.isfinite(table[name].to_numpy()).all(), name


def test_run_leaves_no_temporary_files(run_dir):
    out, _ = run_dir
    assert _hidden(out) == []


def test_rerunning_written_config_gives_identical_results(cli, one_json, run_dir, tmp_path):
    out, record = run_dir
    again = tmp_path / "again"
    proc = cli("run", out / "config.toml", "--out", again, "--json")
    assert proc.returncode == 0, proc.stderr
    second = one_json(proc.stdout)
    assert second["metrics"] == record["metrics"]
    assert second["config_hash"] == record["config_hash"]
    assert (again / "config.toml").read_bytes() == (out / "config.toml").read_bytes()
    assert _trace(again).equals(_trace(out))


def test_run_human_output(cli, tmp_path, write_toml, tiny_config):
    out = tmp_path / "run"
    proc = cli("run", write_toml(tiny_config), "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "noise_rms" in proc.stdout and "written to" in proc.stdout
    assert records.is_finished(out)


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
    assert _hidden(out) == []


def test_sinusoid_run_has_tracking_metrics(tmp_path, tiny_config):
    cfg = {**tiny_config, "duration": 1.0, "settle": 0.5}
    cfg["reference"] = {"amplitude": 0.1, "frequency": 20.0}
    record = runner.run_to_folder(cfg, tmp_path / "sin")
    m = record["metrics"]
    assert m["rise_time"] is None and m["rise_time_feedback"] is None
    assert m["amplitude_ratio"] is not None and m["amplitude_ratio"] > 0
    assert m["phase_lag"] is not None


# ----- records: hashes, versions, records ----------------------------------------------------


def test_config_hash_is_stable_and_order_independent():
    a = {"experiment": "x", "seed": 1, "controller": {"kp": 1.0, "ki": 2.0}}
    b = {"controller": {"ki": 2.0, "kp": 1.0}, "seed": 1, "experiment": "x"}
    h = records.config_hash(a)
    assert h == records.config_hash(b)
    assert len(h) == 12 and all(c in "0123456789abcdef" for c in h)
    assert h != records.config_hash({**a, "seed": 2})
    assert h != records.config_hash({**a, "controller": {"kp": 1.0, "ki": 2.5}})


def test_package_versions_lists_python_and_packages():
    versions = records.package_versions()
    assert set(versions) == {"python", *records._VERSIONED}
    assert all(isinstance(v, str) and v for v in versions.values())


def test_build_record_turns_non_finite_metrics_into_null():
    config = {"experiment": "motor.current", "seed": 7}
    result = Result(
        metrics={"a": 1.5, "b": float("nan"), "c": float("inf"), "d": np.float64(2.0)},
        trace={"t": np.zeros(3)},
    )
    record = records.build_record(config, result, 0.25)
    assert record["metrics"] == {"a": 1.5, "b": None, "c": None, "d": 2.0}
    assert record["seed"] == 7
    assert record["wall_time_s"] == 0.25
    assert record["config_hash"] == records.config_hash(config)
    json.dumps(record, allow_nan=False)  # strict JSON


def test_write_run_and_read_back(tmp_path):
    folder = tmp_path / "deep" / "run"
    config = {"experiment": "motor.current", "seed": 0, "reference": {"current": 1.0}}
    record = {"metrics": {"x": 1.0}, "seed": 0}
    trace = {"t": np.arange(5) * 0.1, "i": np.linspace(0, 1, 5)}
    assert not records.is_finished(folder)
    records.write_run(folder, config, record, trace)
    assert records.is_finished(folder)
    assert records.read_record(folder) == record
    assert tomllib.loads((folder / records.CONFIG).read_text()) == config
    table = _trace(folder)
    assert table.column_names == ["t", "i"]
    np.testing.assert_array_equal(table["i"].to_numpy(), trace["i"])
    assert _hidden(folder) == []


# ----- atomic writes -------------------------------------------------------------------------


def test_atomic_write_replaces_with_a_temporary_file_beside_the_target(tmp_path, monkeypatch):
    path = tmp_path / "file.json"
    path.write_bytes(b"old")
    seen = []
    real_replace = os.replace

    def spy(src, dst):
        seen.append((Path(src), Path(dst), Path(src).read_bytes()))
        real_replace(src, dst)

    monkeypatch.setattr(records.os, "replace", spy)
    records.atomic_write(path, b"new")
    assert path.read_bytes() == b"new"
    [(src, dst, data)] = seen
    assert dst == path
    assert src.parent == path.parent  # same file system, so the rename is atomic
    assert src.name.startswith(".")
    assert data == b"new"  # complete before the rename
    assert _hidden(tmp_path) == []


@pytest.mark.parametrize("fail_at", ["replace", "fsync", "write"])
@pytest.mark.parametrize("error", [OSError("disk on fire"), KeyboardInterrupt()])
def test_atomic_write_failure_keeps_old_file_and_leaves_no_temp(
    tmp_path, monkeypatch, fail_at, error
):
    path = tmp_path / "record.json"
    path.write_bytes(b'{"old": true}')

    def boom(*args, **kwargs):
        raise error

    if fail_at == "replace":
        monkeypatch.setattr(records.os, "replace", boom)
    elif fail_at == "fsync":
        monkeypatch.setattr(records.os, "fsync", boom)
    else:
        real_fdopen = os.fdopen

        class HalfWriter:
            """A file whose write stores half the data and then fails."""

            def __init__(self, fd, mode):
                self._f = real_fdopen(fd, mode)

            def __enter__(self):
                return self

            def __exit__(self, *exc):
                self._f.close()

            def write(self, data):
                self._f.write(data[: len(data) // 2])
                self._f.flush()
                raise error

        monkeypatch.setattr(records.os, "fdopen", HalfWriter)

    with pytest.raises(type(error)):
        records.atomic_write(path, b'{"new": true, "padding": "' + b"x" * 10_000 + b'"}')
    assert path.read_bytes() == b'{"old": true}'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["record.json"]


def test_atomic_write_failure_on_a_new_file_leaves_nothing(tmp_path, monkeypatch):
    def boom(*args, **kwargs):
        raise OSError("no")

    monkeypatch.setattr(records.os, "replace", boom)
    with pytest.raises(OSError):
        records.atomic_write(tmp_path / "x.parquet", b"data")
    assert list(tmp_path.iterdir()) == []


def test_write_run_failing_midway_does_not_mark_the_run_finished(tmp_path, monkeypatch):
    folder = tmp_path / "run"
    real = records.atomic_write

    def failing(path, data):
        if path.name == records.TRACE:
            raise OSError("disk full")
        real(path, data)

    monkeypatch.setattr(records, "atomic_write", failing)
    with pytest.raises(OSError):
        records.write_run(folder, {"experiment": "e"}, {"metrics": {}}, {"t": np.zeros(2)})
    assert not records.is_finished(folder)
    assert not (folder / records.RECORD).exists()
    assert _hidden(folder) == []


def test_failed_record_write_keeps_previous_finished_run(tmp_path, monkeypatch, tiny_config):
    out = tmp_path / "run"
    first = runner.run_to_folder(tiny_config, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    real_replace = os.replace

    def fail_on_record(src, dst):
        if Path(dst).name == records.RECORD:
            raise OSError("power cut")
        real_replace(src, dst)

    monkeypatch.setattr(records.os, "replace", fail_on_record)
    with pytest.raises(OSError):
        runner.run_to_folder({**tiny_config, "seed": 9}, out)
    assert records.read_record(out) == first
    assert (out / records.RECORD).read_bytes() == before[records.RECORD]
    assert _hidden(out) == []


def test_write_table_is_atomic(tmp_path, monkeypatch):
    import pyarrow as pa

    path = tmp_path / "results.parquet"
    records.write_table(path, pa.table({"a": [1, 2]}))
    assert pq.read_table(path).to_pydict() == {"a": [1, 2]}

    def boom(*args, **kwargs):
        raise OSError("no")

    monkeypatch.setattr(records.os, "replace", boom)
    with pytest.raises(OSError):
        records.write_table(path, pa.table({"a": [3]}))
    assert pq.read_table(path).to_pydict() == {"a": [1, 2]}
    assert _hidden(tmp_path) == []
