"""The `articula` app: help, unknown commands, and errors that stay one line."""

from __future__ import annotations

import pytest


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["frobnicate"], ["frobnicate"]),
        (["motor", "frobnicate"], ["frobnicate"]),
        (["--bogus"], ["--bogus"]),
        (["run"], ["config"]),
        (["sweep"], ["spec"]),
    ],
    ids=["command", "subcommand", "option", "run_without_config", "sweep_without_spec"],
)
def test_unknown_command_or_option(cli, assert_one_line_error, args, names):
    proc = cli(*args)
    assert proc.stdout == ""
    assert_one_line_error(proc, *names)


def test_help_exits_zero(cli):
    proc = cli("--help")
    assert proc.returncode == 0
    for command in ("run", "sweep", "reproduce", "motor"):
        assert command in proc.stdout


def test_errors_are_one_line_even_for_long_messages(cli, tmp_path, assert_one_line_error):
    # The pydantic message of a model-level check quotes the whole input mapping.
    path = tmp_path / "cfg.toml"
    path.write_text(
        'experiment = "motor.current"\nduration = 1.0\nsettle = 5.0\n'
        "[reference]\ncurrent = 1.0\n[pwm]\nbits = 8\n[sensor]\nideal = true\n"
    )
    line = assert_one_line_error(cli("run", path, "--out", tmp_path / "o"), "settle", "duration")
    assert line.startswith("error: ")
