"""The long-running commands end alike on Ctrl-C and SIGTERM: `live --record` writes its
session either way (no browser needed), `view`, `live` and `emulate` exit 130 on Ctrl-C and
143 on SIGTERM with one plain line (not a sweep's), and an address that is not this machine's
is blamed on --host."""

from __future__ import annotations

import signal

import pytest

from articula.cli import main
from articula.viewer import replay
from articula.viewer.run_data import load_run
from tests.viewer.conftest import free_port

LINES = {
    signal.SIGTERM: "error: terminated (SIGTERM)\n",
    signal.SIGINT: "error: interrupted (Ctrl-C)\n",
}


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(("sent", "status"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_live_writes_its_record_on_sigterm_as_on_ctrl_c(scene_file, viewer, tmp_path, sent,
                                                        status):  # fmt: skip
    proc, _ = viewer("live", scene_file, "--method", "qp", "--record", tmp_path / "rec")
    proc.send_signal(sent)  # the URL line comes after the first period: there is a session
    assert proc.wait(60) == status
    assert proc.stderr.read() == LINES[sent]
    run = load_run(tmp_path / "rec")
    assert len(run.t) >= 1


@pytest.mark.slow
@pytest.mark.parametrize(("sent", "status"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_view_ends_with_the_signals_status(planned_run, viewer, sent, status):
    proc, _ = viewer("view", planned_run)
    proc.send_signal(sent)
    assert proc.wait(30) == status
    assert proc.stderr.read() == LINES[sent]


def test_ctrl_c_on_a_server_is_a_plain_line_through_the_cli(planned_run, monkeypatch, capsys):
    """Issue 48: Ctrl-C on view, live or emulate printed the sweep's line ("a sweep
    resumes..."). Ctrl-C lands while the page is built, in-process through articula.cli.main."""

    def ctrl_c(*args: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(replay, "Replay", ctrl_c)
    with pytest.raises(SystemExit) as exc:
        main(["view", str(planned_run), "--port", str(free_port())])
    assert exc.value.code == 130
    assert capsys.readouterr().err == "error: interrupted (Ctrl-C)\n"


def test_emulate_ends_with_sigterms_status(emulate_process):
    proc, _ = emulate_process("pneunet")
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(30) == 143


def test_an_address_not_of_this_machine_is_blamed_on_host(planned_run, cli):
    proc = cli("view", planned_run, "--host", "999.1.1.1", "--port", str(free_port()))
    assert proc.returncode == 2 and "--host" in proc.stderr and "--port" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
