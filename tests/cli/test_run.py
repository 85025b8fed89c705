"""`articula run`: the run folder contract, its record, and a re-run of its config.toml."""

from __future__ import annotations

import errno
import json
import math
import os
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from articula.cli import main
from articula.runs import records
from tests.conftest import ARTICULA
from tests.helpers import hidden_files

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


def _trace(folder: Path):
    return pq.read_table(folder / records.TRACE)


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
    assert hidden_files(out) == []


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


@pytest.mark.slow
def test_run_human_output(cli, tmp_path, write_toml, tiny_config):
    out = tmp_path / "run"
    proc = cli("run", write_toml(tiny_config), "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "noise_rms" in proc.stdout and "written to" in proc.stdout
    assert records.is_finished(out)


RUN_CONFIGS = {
    "unknown_key": ('experiment = "motor.current"\ndurration = 1.0\n', ["durration", "unknown"]),
    "unknown_nested_key": (
        'experiment = "motor.current"\n[controller]\nkd = 1.0\n',
        ["controller.kd"],
    ),
    "wrong_type": ('experiment = "motor.current"\nseed = "zero"\n', ["seed"]),
    "nan": ('experiment = "motor.current"\nduration = nan\n', ["duration"]),
    "negative": ('experiment = "motor.current"\nduration = -1.0\n', ["duration"]),
    "negative_motor_resistance": (
        'experiment = "motor.current"\n[motor]\nR = -1.0\nK = 0.4\nb = 0.0\nJ = 0.1\n',
        ["motor.R"],
    ),
    "settle_after_end": (
        'experiment = "motor.current"\nduration = 1.0\nsettle = 2.0\n',
        ["settle"],
    ),
    "bad_literal": ('experiment = "motor.current"\nrig = "triple"\n', ["rig"]),
    "filter_order_zero": (
        'experiment = "motor.current"\n[controller]\nfilter_order = 0\n',
        ["controller.filter_order"],
    ),
    "unknown_experiment": ('experiment = "motor.voltage"\n', ["experiment", "motor.voltage"]),
    "missing_experiment": ("duration = 1.0\n", ["experiment"]),
    "not_toml": ("experiment = motor.current\n", ["cfg.toml"]),
}


@pytest.mark.parametrize("case", sorted(RUN_CONFIGS))
def test_run_bad_config(main_fails, tmp_path, case):
    text, names = RUN_CONFIGS[case]
    path = tmp_path / "cfg.toml"
    path.write_text(text)
    line = main_fails("run", path, "--out", tmp_path / "out", "--json")
    assert all(name in line for name in names), line
    assert not (tmp_path / "out" / "record.json").exists()


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("case", ["unknown_key", "nan", "wrong_type"])
def test_run_bad_config_console_script(cli, tmp_path, assert_one_line_error, case):
    text, names = RUN_CONFIGS[case]
    path = tmp_path / "cfg.toml"
    path.write_text(text)
    proc = cli("run", path, "--out", tmp_path / "out", "--json")
    assert proc.stdout == ""
    assert_one_line_error(proc, *names)
    assert not (tmp_path / "out").exists()


def test_run_missing_config_file(cli, tmp_path, assert_one_line_error):
    proc = cli("run", tmp_path / "nope.toml", "--out", tmp_path / "out")
    assert_one_line_error(proc, "nope.toml")


def test_run_out_is_a_file(cli, tmp_path, write_toml, tiny_config, assert_one_line_error):
    blocker = tmp_path / "blocker"
    blocker.write_text("not a folder")
    proc = cli("run", write_toml(tiny_config), "--out", blocker, "--json")
    assert_one_line_error(proc, "blocker")


@pytest.mark.slow
def test_run_out_under_a_file_is_one_line(
    cli, tmp_path, write_toml, tiny_config, assert_one_line_error
):
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    proc = cli("run", write_toml(tiny_config), "--out", blocker / "sub", "--json")
    assert_one_line_error(proc, "--out")


def test_reference_the_supply_cannot_reach_is_rejected(
    main_fails, tmp_path, write_toml, tiny_config
):
    # 1.5 A at 5 rad/s needs 1.5·8.35 + 0.4485·5 = 14.8 V, more than the 12 V supply (Eq. 4.13).
    config = write_toml({**tiny_config, "reference": {"current": 1.5}})
    assert "reference" in main_fails("run", config, "--out", tmp_path / "out", "--json")


def _full_disk_outcome(out) -> None:
    """What a full disk must leave: no record, so that nothing takes the run as finished."""
    assert not (out / records.RECORD).exists()
    assert not records.is_finished(out)
    if out.exists():
        assert hidden_files(out) == []


@pytest.mark.slow
def test_a_full_disk_is_one_line_exit_1_and_no_finished_run(tmp_path, write_toml, tiny_config):
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(disk)],
        capture_output=True, check=False,
    )  # fmt: skip
    if mounted.returncode != 0:
        pytest.skip("mounting a tmpfs needs root (CI runs as root); the injected test covers it")
    try:
        config = write_toml({**tiny_config, "duration": 20.0, "settle": 1.0})  # ~1.4 MB trace
        out = disk / "run"
        proc = subprocess.run(
            [ARTICULA, "run", str(config), "--out", str(out), "--json"],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        assert proc.returncode == 1, proc.stderr
        (line,) = proc.stderr.splitlines()
        assert line.startswith("error: ") and "No space left on device" in line
        _full_disk_outcome(out)
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_an_injected_full_disk_is_one_line_exit_1_and_no_finished_run(
    tmp_path, write_toml, tiny_config, monkeypatch, capsys
):
    calls = []

    def fsync(fd):
        calls.append(fd)
        if len(calls) == 3:  # config.toml and its folder are on disk; the trace does not fit
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(records.os, "fsync", fsync)
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as exc:
        main(["run", str(write_toml(tiny_config)), "--out", str(out), "--json"])
    assert exc.value.code == 1
    (line,) = capsys.readouterr().err.splitlines()
    assert line == f"error: {out / records.TRACE}: No space left on device"
    _full_disk_outcome(out)


@pytest.mark.slow
def test_a_folder_of_someone_elses_files_is_refused_and_left_as_it_was(
    cli, tmp_path, write_toml, tiny_config, assert_one_line_error
):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "config.toml").write_text("my own notes")
    (out / "thesis.tex").write_text("chapter 1")
    proc = cli("run", write_toml(tiny_config), "--out", out, "--json")
    assert_one_line_error(proc, "--out", "thesis.tex", "--force")
    assert (out / "config.toml").read_text() == "my own notes"
    forced = cli("run", write_toml(tiny_config), "--out", out, "--force", "--json")
    assert forced.returncode == 0, forced.stderr
    assert (out / "thesis.tex").read_text() == "chapter 1"
    assert records.is_finished(out)


def test_warnings_of_a_failing_command_do_not_add_lines(monkeypatch, main_fails, tmp_path):
    from articula.errors import ConfigError
    from articula.runs import runner

    def warn_then_fail(*args, **kwargs):
        np.log(np.zeros(1))  # a RuntimeWarning, as numerical code raises
        raise ConfigError("field", "bad")

    monkeypatch.setattr(runner, "run_to_folder", warn_then_fail)
    config = tmp_path / "c.toml"
    config.write_text('experiment = "motor.current"\n')
    assert main_fails("run", config, "--out", tmp_path / "o") == "error: field: bad"
