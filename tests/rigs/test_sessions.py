"""Two hosts, one after the other, on one device: each host counts its sequence numbers from
0, so the second host's START can take the seq of the first one's; a HELLO opens a new session
and that START is a new run, not a resend acknowledged without running (it was: the second
`rig run` of the same config on an emulated motor came back "complete" with 0 samples)."""

from __future__ import annotations

from pathlib import Path

import tomli_w

from articula.book.study import packaged
from articula.experiments.rig_sessions import run_config
from articula.validation import load_toml


def run_sessions(port: str, folder: Path, count: int = 3) -> list[int]:
    """The samples of `count` runs of one motor.current config, each a session of its own."""
    config = folder / "motor.toml"
    data = load_toml(packaged("ch4", "fig4_5.toml")) | {"duration": 0.5, "settle": 0.25}
    config.write_text(tomli_w.dumps(data))
    return [run_config(port, config, folder / f"run{k}")["samples"] for k in range(count)]


def test_each_session_on_the_python_device_runs(emulate_process, tmp_path):
    _, port = emulate_process("motor")
    assert run_sessions(port, tmp_path) == [500, 500, 500]
