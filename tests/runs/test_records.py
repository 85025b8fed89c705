"""Run folders: hashes, versions, records, and atomic writes."""

from __future__ import annotations

import json
import os
import tomllib
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from articula.runs import records, runner
from articula.runs.registry import Result
from tests.helpers import hidden_files


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
    table = pq.read_table(folder / records.TRACE)
    assert table.column_names == ["t", "i"]
    np.testing.assert_array_equal(table["i"].to_numpy(), trace["i"])
    assert hidden_files(folder) == []


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
    assert hidden_files(tmp_path) == []


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
    assert hidden_files(folder) == []


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
    assert hidden_files(out) == []


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
    assert hidden_files(tmp_path) == []
