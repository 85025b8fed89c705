"""`articula sweep`: the same numbers on every backend, resume after a kill, nothing recomputed."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from articula.runs import records, runner, sweep
from tests.helpers import hidden_files, run_folders, write_spec

BASE = {"experiment": "motor.current", "duration": 0.5, "settle": 0.2}


# 2 seeds x 2 filter orders x (constant, sinusoid) = 8 runs, each a few milliseconds.
SPEC = {
    "base": BASE,
    "grid": {"seed": [0, 1], "controller.filter_order": [1, 4]},
    "runs": [{}, {"reference": {"amplitude": 0.1, "frequency": 40.0}}],
}


def _results(out: Path) -> dict[str, list]:
    """results.parquet without the wall-clock column, as plain lists."""
    table = pq.read_table(out / runner.RESULTS)
    return table.drop_columns(["wall_time_s"]).to_pydict()


def _assert_same_sweep(a: Path, b: Path) -> None:
    """Two sweep folders hold identical configs, metrics and traces (wall times aside)."""
    assert _results(a) == _results(b)
    assert run_folders(a) == run_folders(b)
    for name in run_folders(a):
        assert (a / name / records.CONFIG).read_bytes() == (b / name / records.CONFIG).read_bytes()
        ra, rb = records.read_record(a / name), records.read_record(b / name)
        assert ra["metrics"] == rb["metrics"], name
        assert ra["config_hash"] == rb["config_hash"] == name
        ta = pq.read_table(a / name / records.TRACE)
        tb = pq.read_table(b / name / records.TRACE)
        assert ta.equals(tb), name


@pytest.fixture(scope="module")
def sweep_spec(tmp_path_factory) -> Path:
    return write_spec(tmp_path_factory.mktemp("spec") / "sweep.toml", SPEC)


@pytest.fixture(scope="module")
def serial_sweep(sweep_cli, sweep_spec, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("serial") / "out"
    sweep_cli(sweep_spec, out, "--workers", "1")
    return out


def test_serial_sweep_layout(serial_sweep):
    configs = sweep.expand_sweep(SPEC)
    assert len(configs) == 8
    assert run_folders(serial_sweep) == sorted(records.config_hash(c) for c in configs)
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
    assert hidden_files(serial_sweep) == []


def test_process_pool_gives_identical_numbers(sweep_cli, sweep_spec, serial_sweep, tmp_path):
    out = tmp_path / "pool"
    sweep_cli(sweep_spec, out, "--workers", "2")
    _assert_same_sweep(serial_sweep, out)
    assert hidden_files(out) == []


@pytest.mark.slow
def test_dask_local_gives_identical_numbers(sweep_cli, sweep_spec, serial_sweep, tmp_path):
    out = tmp_path / "dask"
    sweep_cli(sweep_spec, out, "--dask", "local", "--workers", "2")
    _assert_same_sweep(serial_sweep, out)
    assert hidden_files(out) == []


@pytest.mark.slow
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


@pytest.mark.slow
def test_killed_sweep_resumes_without_recomputing_finished_runs(
    sweep_cli, articula_script, tmp_path
):
    spec = write_spec(tmp_path / "slow.toml", SLOW_SPEC)
    out = tmp_path / "out"
    configs = sweep.expand_sweep(SLOW_SPEC)
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
        assert hidden_files(folder) == [], name  # no half-written file in a finished run
        assert sorted(p.name for p in folder.iterdir()) == [
            records.CONFIG,
            records.RECORD,
            records.TRACE,
        ]
        pq.read_table(folder / records.TRACE)  # complete and readable
        before[name] = _snapshot(folder)

    summary = sweep_cli(spec, out, "--workers", "2")
    assert summary["runs"] == SLOW_RUNS
    assert summary["skipped"] == len(finished)  # it says what it did not recompute

    assert set(_finished(out)) == set(hashes)
    for name, snap in before.items():
        assert _snapshot(out / name) == snap, f"finished run {name} was rewritten"
        assert hidden_files(out / name) == []
    results = pq.read_table(out / runner.RESULTS)
    assert results.column("run").to_pylist() == hashes
    assert results.column("seed").to_pylist() == list(range(SLOW_RUNS))

    # A run that was still missing at the kill now holds the numbers of a clean run.
    missing = [i for i, h in enumerate(hashes) if h not in finished]
    i = missing[0]
    fresh = runner.execute(configs[i])
    assert records.read_record(out / hashes[i])["metrics"] == fresh.record["metrics"]


SWEEP_SPECS = {
    "missing_file": (None, ["nope.toml"]),
    "not_toml": ("[base\n", ["sweep.toml"]),
    "unknown_sweep_key": ("[base]\n{base}\n[grids]\nseed = [0]\n", ["grids"]),
    "grid_not_a_list": ("[base]\n{base}\n[grid]\nseed = 3\n", ["grid.seed"]),
    "grid_empty_list": ("[base]\n{base}\n[grid]\nseed = []\n", ["grid.seed"]),
    "bad_grid_key": ('[base]\n{base}\n[grid]\n"controller.kd" = [1.0]\n', ["controller.kd"]),
    "bad_grid_value": ("[base]\n{base}\n[grid]\nseed = [0, -1]\n", ["seed"]),
    "grid_nan_value": ("[base]\n{base}\n[grid]\nduration = [1.0, nan]\n", ["duration"]),
    "grid_through_scalar": ('[base]\n{base}\nseed = 0\n[grid]\n"seed.x" = [1]\n', ["seed.x"]),
    "duplicate_points": ("[base]\n{base}\n[grid]\nseed = [1, 1]\n", ["grid"]),
    "bad_run_entry": ('[base]\n{base}\n[[runs]]\nrig = "triple"\n', ["rig"]),
    "missing_experiment": ("[grid]\nseed = [0, 1]\n", ["experiment"]),
}


_BASE = 'experiment = "motor.current"\nduration = 0.2\nsettle = 0.1'


def _sweep_file(tmp_path: Path, text: str | None) -> Path:
    if text is None:
        return tmp_path / "nope.toml"
    path = tmp_path / "sweep.toml"
    path.write_text(text.format(base=_BASE))
    return path


@pytest.mark.parametrize("case", sorted(SWEEP_SPECS))
def test_sweep_bad_spec(main_fails, tmp_path, case):
    text, names = SWEEP_SPECS[case]
    out = tmp_path / "out"
    line = main_fails("sweep", _sweep_file(tmp_path, text), "--out", out, "--json")
    assert all(name in line for name in names), line
    assert not out.exists()  # a bad sweep fails before anything runs


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("case", ["bad_grid_key", "duplicate_points", "missing_file"])
def test_sweep_bad_spec_console_script(cli, tmp_path, assert_one_line_error, case):
    text, names = SWEEP_SPECS[case]
    out = tmp_path / "out"
    proc = cli("sweep", _sweep_file(tmp_path, text), "--out", out, "--json")
    assert proc.stdout == ""
    assert_one_line_error(proc, *names)
    assert not out.exists()


@pytest.mark.parametrize(
    "spec",
    [
        pytest.param("base = 3\n", id="base_not_a_table"),
        pytest.param("runs = 3\n[base]\n{base}\n", id="runs_not_a_list"),
        pytest.param("runs = [1, 2]\n[base]\n{base}\n", id="runs_entry_not_a_table"),
        pytest.param("grid = [1]\n[base]\n{base}\n", id="grid_not_a_table"),
    ],
)
def test_sweep_spec_sections_of_wrong_type(main_fails, tmp_path, spec):
    path = tmp_path / "sweep.toml"
    path.write_text(spec.format(base=_BASE))
    main_fails("sweep", path, "--out", tmp_path / "out", "--json")


@pytest.mark.parametrize(
    ("option", "name"),
    [
        (["--workers", "0"], "--workers"),
        (["--workers", "two"], "--workers"),
        (["--dask", "udp://127.0.0.1:1"], "--dask"),
    ],
    ids=["workers_zero", "workers_not_a_number", "dask_bad_address"],
)
def test_sweep_bad_options(main_fails, tmp_path, write_toml, tiny_config, option, name):
    spec = write_toml({"base": tiny_config}, "sweep.toml")
    line = main_fails("sweep", spec, "--out", tmp_path / "out", *option, "--json")
    assert name in line


def test_sweep_bad_dask_without_json_is_one_line(
    cli, tmp_path, write_toml, tiny_config, assert_one_line_error
):
    spec = write_toml({"base": tiny_config}, "sweep.toml")
    proc = cli("sweep", spec, "--out", tmp_path / "out", "--dask", "bogus")
    assert_one_line_error(proc, "--dask")


def _session_processes(session: int) -> list[int]:
    """Pids of the live processes of a session (Linux /proc)."""
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue  # gone meanwhile
        if int(fields[3]) == session and fields[0] != "Z":
            pids.append(int(entry.name))
    return pids


def _wait_until(condition, seconds: float) -> bool:
    """Poll `condition` until it holds or `seconds` pass (a safety net, not a timing check)."""
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("backend", [[], ["--dask", "local"]], ids=["pool", "dask"])
def test_a_killed_sweep_leaves_no_worker_behind(articula_script, tmp_path, backend):
    spec = write_spec(tmp_path / "slow.toml", SLOW_SPEC)
    command = [articula_script, "sweep", str(spec), "--out", str(tmp_path / "out")]
    proc = subprocess.Popen(
        [*command, "--workers", "2", *backend],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )  # fmt: skip
    try:
        # The pool's workers are up once a run has finished.
        assert _wait_until(lambda: bool(_finished(tmp_path / "out")), 600)
        assert len(_session_processes(proc.pid)) >= 3  # the sweep and its workers
        os.kill(proc.pid, signal.SIGKILL)  # the parent only, as an OOM killer would
        proc.wait()
        assert _wait_until(lambda: not _session_processes(proc.pid), 10), (
            f"left behind: {_session_processes(proc.pid)}"
        )
    finally:
        for pid in _session_processes(proc.pid):
            os.kill(pid, signal.SIGKILL)


@pytest.mark.slow
def test_two_sweeps_into_one_folder_end_in_one_refusal_or_shared_results(articula_script, tmp_path):
    spec = write_spec(tmp_path / "slow.toml", SLOW_SPEC)
    out = tmp_path / "out"
    command = [articula_script, "sweep", str(spec), "--out", str(out), "--workers", "1"]
    procs = [subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for _ in range(2)]  # fmt: skip
    results = [(p.wait(), p.stdout.read(), p.stderr.read()) for p in procs]
    for p in procs:
        p.stdout.close()
        p.stderr.close()
    codes = sorted(code for code, _, _ in results)
    assert codes in ([0, 0], [0, 1]), results
    for code, _, err in results:
        assert "Traceback" not in err
        if code == 1:
            (line,) = err.splitlines()
            assert line.startswith("error: --out:") and "another process (pid " in line
    assert pq.read_table(out / runner.RESULTS).num_rows == SLOW_RUNS
    assert set(_finished(out)) == {records.config_hash(c) for c in sweep.expand_sweep(SLOW_SPEC)}
    assert hidden_files(out) == []


@pytest.mark.slow
def test_a_sweep_resumes_past_run_folders_that_were_left_incomplete(sweep_cli, tmp_path):
    spec = write_spec(tmp_path / "s.toml", SPEC)
    out = tmp_path / "out"
    sweep_cli(spec, out)
    hashes = run_folders(out)
    (out / hashes[0] / records.TRACE).unlink()  # a run killed between its files
    (out / hashes[1] / records.RECORD).write_text('{"metrics": ')  # a truncated record
    (out / hashes[2] / ".record.json.k1ll3d00.tmp").write_text("half")  # a killed write
    (out / ".results.parquet.k1ll3d00.tmp").write_text("half")
    written = {h: (out / h / records.RECORD).stat().st_mtime_ns for h in hashes[3:]}
    sweep_cli(spec, out)
    for h in hashes[:2]:
        assert records.is_finished(out / h, h)
    assert {h: (out / h / records.RECORD).stat().st_mtime_ns for h in hashes[3:]} == written
    assert hidden_files(out) == []
