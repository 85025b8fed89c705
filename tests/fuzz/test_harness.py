"""The harness itself: the fork server runs the real CLI and sees crashes, hangs, runaway
memory and processes; the contract check names each kind of violation."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import pytest

from tests.fuzz import bases
from tests.fuzz.client import ForkServer, Outcome
from tests.fuzz.contract import Example, listing, violations
from tests.fuzz.inputs import write_toml
from tests.fuzz.server import MAX_PROCESSES

pytestmark = pytest.mark.fuzz


def _dir(tmp_path: Path) -> Path:
    bases.write_support_files(tmp_path)
    return tmp_path


def test_server_is_single_threaded(fuzz_server: ForkServer):
    assert fuzz_server.threads() == 1


def test_good_command_gives_0_and_its_json(fuzz_server: ForkServer, tmp_path: Path):
    write_toml(tmp_path / "c.toml", bases.MOTOR_CURRENT)
    outcome = fuzz_server.run(["run", "c.toml", "--out", "out", "--json"], tmp_path)
    assert (outcome.status, outcome.signal, outcome.stderr) == (0, None, "")
    record = json.loads(outcome.stdout)
    assert record["experiment"] == "motor.current"
    assert (tmp_path / "out" / "record.json").is_file()  # the child ran in `cwd`
    assert outcome.wall < 10


def test_bad_command_gives_2_and_one_line(fuzz_server: ForkServer, tmp_path: Path):
    outcome = fuzz_server.run(["motor", "analyze", "--preset", "nope"], tmp_path)
    assert outcome.status == 2
    assert outcome.stderr.startswith("error:")
    assert len(outcome.stderr.splitlines()) == 1
    assert outcome.stdout == ""


def test_segfault_is_reported_as_a_signal(fuzz_server: ForkServer, tmp_path: Path):
    outcome = fuzz_server.run([], tmp_path, probe="segfault")
    assert outcome.status is None
    assert outcome.signal == signal.SIGSEGV
    assert not outcome.timed_out
    assert "Fatal Python error" in outcome.stderr  # faulthandler names the Python line
    example = Example("probe", [], tmp_path)
    assert any("SIGSEGV" in p for p in violations(example, outcome, listing(tmp_path)))


def test_hang_is_killed_at_the_timeout(fuzz_server: ForkServer, tmp_path: Path):
    outcome = fuzz_server.run([], tmp_path, timeout=1.0, probe="sleep", seconds=600)
    assert outcome.timed_out
    assert outcome.signal == signal.SIGKILL
    assert 1.0 <= outcome.wall < 10


def test_memory_limit_stops_a_runaway_allocation(fuzz_server: ForkServer, tmp_path: Path):
    outcome = fuzz_server.run([], tmp_path, probe="allocate", bytes=8 << 30)
    assert outcome.status == 99
    assert "MemoryError" in outcome.stderr


def test_uncaught_exception_is_status_99_with_its_traceback(
    fuzz_server: ForkServer, tmp_path: Path
):
    outcome = fuzz_server.run([], tmp_path, probe="raise")
    assert outcome.status == 99
    assert "Traceback (most recent call last)" in outcome.stderr
    assert "RuntimeError: probe" in outcome.stderr


def test_processes_left_behind_are_reported_and_killed(fuzz_server: ForkServer, tmp_path: Path):
    outcome = fuzz_server.run([], tmp_path, probe="spawn")
    assert outcome.status == 0
    assert outcome.leftover
    example = Example("probe", [], tmp_path)
    assert any("outlived it" in p for p in violations(example, outcome, listing(tmp_path)))


def test_a_runaway_process_count_is_stopped(fuzz_server: ForkServer, tmp_path: Path):
    outcome = fuzz_server.run([], tmp_path, probe="spawn", count=MAX_PROCESSES + 30, seconds=30)
    assert outcome.too_many_processes
    assert outcome.processes > MAX_PROCESSES
    assert outcome.signal == signal.SIGKILL


def test_server_survives_its_children(fuzz_server: ForkServer, tmp_path: Path):
    fuzz_server.run([], tmp_path, probe="segfault")
    outcome = fuzz_server.run(["motor", "analyze", "--preset", "table4.1", "--json"], tmp_path)
    assert outcome.status == 0
    assert json.loads(outcome.stdout)["params"]["R"] == pytest.approx(8.35)


def _outcome(status: int | None, stderr: str = "", stdout: str = "", **kw) -> Outcome:
    fields = {"signal": None, "timed_out": False, "wall": 0.1, "maxrss_kb": 1, "leftover": False}
    return Outcome(status=status, stdout=stdout, stderr=stderr, **{**fields, **kw})


def test_contract_accepts_a_clean_refusal_and_a_clean_success(tmp_path: Path):
    example = Example("x", [], _dir(tmp_path), out=tmp_path / "out", as_json=True,
                      finite=["metrics.a"])  # fmt: skip
    before = listing(tmp_path)
    assert violations(example, _outcome(2, "error: a: bad\n"), before) == []
    good = _outcome(0, stdout='{"metrics": {"a": 1.5}}\n')
    assert violations(example, good, before) == []


@pytest.mark.parametrize(
    ("outcome", "problem"),
    [
        (_outcome(1, "error: x\n"), "exit status 1"),
        (_outcome(2, "Traceback (most recent call last):\nValueError: x\n"), "traceback"),
        (_outcome(2, "warning\nerror: x\n"), "2 stderr lines"),
        (_outcome(2, ""), "0 stderr lines"),
        (_outcome(2, "error:  \n"), "non-empty `error:`"),
        (_outcome(2, "error: x\n", wall=30.0), "refusal after 30.0 s"),
        (_outcome(None, signal=signal.SIGSEGV), "SIGSEGV"),
        (_outcome(None, signal=signal.SIGKILL, timed_out=True, wall=60.0), "no answer within"),
        (_outcome(0, "RuntimeWarning: overflow\n", '{"metrics": {"a": 1}}'), "on stderr"),
        (_outcome(0, "", '{"metrics": {"a": null}}'), "metrics.a not a finite number"),
        (_outcome(0, "", '{"a": 1}\n{"b": 2}'), "not one JSON object"),
    ],
)
def test_contract_names_each_violation(tmp_path: Path, outcome: Outcome, problem: str):
    example = Example("x", [], _dir(tmp_path), out=tmp_path / "out", as_json=True,
                      finite=["metrics.a"])  # fmt: skip
    found = violations(example, outcome, listing(tmp_path))
    assert any(problem in p for p in found), found


def test_contract_sees_what_a_refusal_wrote(tmp_path: Path):
    example = Example("x", [], _dir(tmp_path), out=tmp_path / "out")
    before = listing(tmp_path)
    (tmp_path / "out").mkdir()
    (tmp_path / ".config.toml.x.tmp").write_text("")
    found = violations(example, _outcome(2, "error: x\n"), before)
    assert any("--out folder out/" in p for p in found), found
    assert any("refusal wrote" in p and ".config.toml.x.tmp" in p for p in found), found


def test_contract_sees_a_user_file_changed_even_on_success(tmp_path: Path):
    example = Example("x", [], _dir(tmp_path), out=None, as_json=False)
    (tmp_path / "notes.txt").write_text("mine")
    before = listing(tmp_path)
    (tmp_path / "notes.txt").write_text("clobbered")
    found = violations(example, _outcome(0, stdout="done"), before)
    assert any("changed or removed files it did not write: notes.txt" in p for p in found)
