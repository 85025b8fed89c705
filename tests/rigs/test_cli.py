"""`articula emulate` and `articula rig info` as a user runs them: real processes, a real
pseudo-terminal; errors are one line, exit 2."""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from articula.book.ch2.study import ziegler_nichols_at_90
from articula.book.ch2.tuning import AutoConfig, ManualConfig, TuningConfig, auto_run, manual_run
from articula.book.study import packaged
from tests.conftest import ARTICULA

PID_CONFIG = """
experiment = "pneunet.pid"
seed = 3
trials = 2
duration = 4.0
[reference]
kind = "sinusoid"
offset_deg = 45.0
amplitude_deg = 30.0
frequency = 0.25
[controller]
gains = [[2.0, 1.5, 0.05]]
"""


def emulate(*options: str) -> tuple[subprocess.Popen, str]:
    """`articula emulate pneunet <options>` started; (its process, its device path)."""
    proc = subprocess.Popen([ARTICULA, "emulate", "pneunet", *options], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)  # fmt: skip
    line = proc.stdout.readline()
    assert "pneunet rig at /dev/" in line, proc.stderr.read()
    return proc, line.split(" at ")[1].split()[0]


@pytest.fixture
def emulated_pneunet():
    """`articula emulate pneunet --fast` running; its device path."""
    proc, path = emulate("--fast")
    yield path
    proc.send_signal(signal.SIGINT)
    assert proc.wait(10) == 130  # interrupted, as every command is
    assert proc.stderr.read().startswith("error: interrupted (Ctrl-C)")


@pytest.fixture
def pid_config(tmp_path):
    """A short chapter-2 PID config (two trials of 4 s on a sinusoid)."""
    path = tmp_path / "pid.toml"
    path.write_text(PID_CONFIG)
    return path


def test_rig_run_writes_a_run_folder_with_the_lines_losses(emulated_pneunet, pid_config, cli,
                                                          tmp_path):  # fmt: skip
    proc = cli("rig", "run", emulated_pneunet, pid_config, "--out", tmp_path / "run", "--json")
    assert proc.returncode == 0, proc.stderr
    record = json.loads(proc.stdout)
    assert record["complete"] and record["samples"] == 2 * 120
    assert record["link"]["crc_errors"] == record["link"]["dropped"] == 0
    assert 0 < record["metrics"]["error_median_deg"] < 45
    trace = pq.read_table(tmp_path / "run" / "trace.parquet").to_pydict()
    assert set(trace) == {"t", "trial", "theta_ref_deg", "theta_meas_deg", "pwm"}
    journal = (tmp_path / "run" / "telemetry.csv").read_text().splitlines()
    assert len(journal) == 1 + 240  # a header, then every sample as it came


ENDINGS = {  # how a run is cut short: exit status, and what its one line says
    "reset": (1, "restarted"),
    "unplug": (1, "went down"),
    "ctrl-c": (130, "interrupted"),
}


def wait_for_samples(journal: Path, count: int, run: subprocess.Popen) -> None:
    """Until the run's telemetry.csv holds `count` samples (it is flushed every 0.1 s)."""
    while run.poll() is None:
        if journal.is_file() and len(journal.read_text().splitlines()) > count:
            return
        time.sleep(0.05)  # polling the file: what is awaited is its content, not a time
    raise AssertionError(f"the run ended first: {run.stderr.read()}")


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("ending", list(ENDINGS))
def test_a_run_cut_short_keeps_what_came_and_says_why(pid_config, tmp_path, ending):
    options = ["--realtime", "--faults", "reset_at=1.0"] if ending == "reset" else ["--realtime"]
    emulator, path = emulate(*options)
    status, words = ENDINGS[ending]
    try:
        run = subprocess.Popen([ARTICULA, "rig", "run", path, pid_config, "--out",
                                tmp_path / "run"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)  # fmt: skip
        if ending != "reset":  # act once samples have come: the run is under way
            wait_for_samples(tmp_path / "run" / "telemetry.csv", 15, run)
        if ending == "unplug":
            emulator.kill()
        elif ending == "ctrl-c":
            run.send_signal(signal.SIGINT)
        assert run.wait(30) == status
        error = run.stderr.read().strip().splitlines()
        assert len(error) == 1 and words in error[0]
    finally:
        emulator.kill()
    record = json.loads((tmp_path / "run" / "record.json").read_text())
    assert not record["complete"] and words in record["incomplete"]
    rows = pq.read_table(tmp_path / "run" / "trace.parquet").num_rows
    assert 10 < rows == record["samples"] < 240


@pytest.mark.slow
def test_rig_info_of_an_emulated_pneunet(emulated_pneunet, cli):
    proc = cli("rig", "info", emulated_pneunet, "--json")
    assert proc.returncode == 0, proc.stderr
    info = json.loads(proc.stdout)
    assert info["rig"] == "pneunet" and info["protocol"] == 2 and info["reset"] == "power-on"
    assert [c["unit"] for c in info["channels"]] == ["deg", "deg", "counts"]
    text = cli("rig", "info", emulated_pneunet).stdout
    assert "angle [deg]" in text


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["rig", "info", "/dev/no-such-rig"], "cannot open the port"),
        (["rig", "info", "/dev/null"], "cannot open the port"),
        (["emulate", "wobble"], "no rig called 'wobble'"),
        (["emulate", "six-chamber", "--plant", "/no/plant.toml"], "plant.toml"),
        (["emulate", "pneunet", "--faults", "drop=3"], "probability"),
        (["emulate", "motor", "--firmware", "/no/motor.elf"], "make -C firmware"),
        (["emulate", "pneunet", "--firmware", "x.elf", "--faults", "drop=0.1"], "not on firmware"),
    ],
)
def test_bad_ports_and_options_are_one_line_and_exit_2(cli, args, words):
    proc = cli(*args)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and words in proc.stderr


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    "command",
    [["record", "--duration", "1"], ["tune"], ["run", str(packaged("ch4", "fig4_5.toml"))]],
    ids=["record", "tune", "run"],
)
def test_a_port_that_does_not_open_leaves_no_output_folder(cli, tmp_path, command):
    verb, *rest = command
    proc = cli("rig", verb, "/dev/no-such-rig", *rest, "--out", tmp_path / "out")
    assert proc.returncode == 2 and "cannot open the port" in proc.stderr, proc.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
@pytest.mark.parametrize(
    ("content", "words"),
    [
        (b"", "is empty, not a firmware ELF"),
        (b"\x12\x9a" * 500, "is not an ELF file"),
        (
            b"\x7fELF\x02\x01\x01" + bytes(9) + b"\x02\x00\x3e\x00" + bytes(44),
            "is an ELF for x86-64, not for the AVR",
        ),
    ],
    ids=["empty", "random", "x86-64"],
)
def test_a_firmware_file_that_is_not_the_rigs_is_refused_naming_it(cli, tmp_path, content,
                                                                    words):  # fmt: skip
    elf = tmp_path / "motor.elf"
    elf.write_bytes(content)
    proc = cli("emulate", "motor", "--firmware", elf)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [proc.stderr.strip()]  # one line
    assert f"error: --firmware: {elf} {words}" in proc.stderr


@pytest.mark.slow
def test_a_recording_runs_again_from_its_config(emulated_pneunet, cli, tmp_path):
    settings = tmp_path / "pid.toml"
    settings.write_text(PID_CONFIG)  # leaves its gains and sinusoid on the rig
    assert cli("rig", "run", emulated_pneunet, settings, "--out", tmp_path / "pid").returncode == 0
    first = cli("rig", "record", emulated_pneunet, "--duration", "1", "--seed", "4", "--out",
                tmp_path / "rec", "--json")  # fmt: skip
    assert first.returncode == 0, first.stderr
    config = tmp_path / "rec" / "config.toml"
    text = config.read_text()
    assert 'experiment = "rig.record"' in text and "[settings.gains]" in text
    assert 'shape = "sinusoid"' in text  # what the rig held: PID_CONFIG's reference
    again = cli("rig", "run", emulated_pneunet, config, "--out", tmp_path / "again", "--json")
    assert again.returncode == 0, again.stderr
    traces = [pq.read_table(tmp_path / name / "trace.parquet").to_pydict()
              for name in ("rec", "again")]  # fmt: skip
    assert traces[0] == traces[1] and len(traces[0]["t"]) == 30


@pytest.mark.slow
def test_rig_tune_reaches_the_in_process_gains(emulated_pneunet, cli, tmp_path):
    config = tmp_path / "tuning.toml"
    config.write_text("[auto]\nseed = 2000\nhold = 2.0\nmax_iterations = 5\n")
    proc = cli("rig", "tune", emulated_pneunet, "--config", config, "--levels", "30,60",
               "--out", tmp_path / "tune", "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    tuning = TuningConfig(auto=AutoConfig(seed=2000, hold=2.0, max_iterations=5))
    here = auto_run(tuning, (30.0, 60.0), 0).result
    assert result["experiments"] == here.evaluations
    assert result["gains"] == pytest.approx(here.k.tolist(), rel=1e-4)
    assert json.loads((tmp_path / "tune" / "tuning.json").read_text()) == result


@pytest.mark.slow
def test_rig_record_takes_every_channel(emulated_pneunet, cli, tmp_path):
    proc = cli("rig", "record", emulated_pneunet, "--duration", "2", "--out", tmp_path / "rec",
               "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["samples"] == 60  # 2 s at 30 Hz
    trace = pq.read_table(tmp_path / "rec" / "trace.parquet").to_pydict()
    assert list(trace) == ["t", "reference", "angle", "pwm"]


@pytest.mark.slow
def test_rig_run_of_fig_4_6_on_the_emulated_motor_rig_is_articula_run(cli, tmp_path):
    config = packaged("ch4", "fig4_6.toml")
    proc = subprocess.Popen([ARTICULA, "emulate", "motor", "--plant", str(config)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        path = proc.stdout.readline().split(" at ")[1].split()[0]
        on_rig = cli("rig", "run", path, config, "--out", tmp_path / "rig", "--json")
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(10)
    assert on_rig.returncode == 0, on_rig.stderr
    here = json.loads(cli("run", config, "--out", tmp_path / "here", "--json").stdout)
    rig = json.loads(on_rig.stdout)
    assert rig["samples"] == 6000
    for key, value in here["metrics"].items():  # null: a metric this run has not (NaN)
        expected = None if value is None else pytest.approx(value, rel=1e-5, abs=1e-6)
        assert rig["metrics"][key] == expected, key


@pytest.mark.slow
def test_a_config_for_another_rig_is_one_line_and_exit_2(emulated_pneunet, cli, tmp_path):
    proc = cli("rig", "run", emulated_pneunet, packaged("ch4", "fig4_5.toml"), "--out",
               tmp_path / "run")  # fmt: skip
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        f"error: {emulated_pneunet}: a pneunet rig, not a motor rig"]  # fmt: skip
    assert not (tmp_path / "run").exists()  # a refused run writes nothing


@pytest.mark.slow
@pytest.mark.parametrize("method", ["manual", "ziegler-nichols"])
def test_rig_tune_runs_chapter_2s_other_tuners_as_in_process(emulated_pneunet, cli, tmp_path,
                                                             method):  # fmt: skip
    config = tmp_path / "tuning.toml"
    config.write_text("[manual]\nseed = 1000\nhold = 4.0\n")
    proc = cli("rig", "tune", emulated_pneunet, "--method", method, "--config", config,
               "--levels", "90", "--out", tmp_path / "tune", "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    tuning = TuningConfig(manual=ManualConfig(seed=1000, hold=4.0))
    if method == "manual":
        here = manual_run(tuning, 90.0)
        assert result["experiments"] == len(here.trials)
        assert result["gains"] == pytest.approx(here.gains.tolist(), rel=1e-4)
    else:
        here = ziegler_nichols_at_90(tuning)
        assert (result["ku"], result["tu_s"]) == pytest.approx((here.ku, here.tu), rel=1e-4)
        assert result["gains"] == pytest.approx(here.pid.tolist(), rel=1e-4)


@pytest.mark.parametrize("command", [["run", "/dev/null", "cfg.toml"], ["record", "/dev/null",
                                     "--duration", "1"], ["tune", "/dev/null"],
                                     ["identify", "/dev/null"]])  # fmt: skip
def test_an_rt_priority_out_of_range_is_one_line_naming_it(main_fails, tmp_path, command):
    line = main_fails("rig", *command, "--out", tmp_path / "o", "--rt-priority", "0")
    assert "--rt-priority" in line
    assert not (tmp_path / "o").exists()
