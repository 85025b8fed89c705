"""Shared fixtures: a tiny fast experiment config, TOML writing and the real console script."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import pytest
import tomli_w

# A shell without job control starts a background job with SIGINT ignored, and a process
# inherits that: the Ctrl-C tests' commands would then never see their SIGINT. Handle it here,
# so that every command the tests start begins with SIGINT at its default (exec resets a
# handler, not an ignored signal).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# The console script installed beside the interpreter running the tests (the venv's).
_SCRIPT = Path(sys.executable).with_name("articula")
ARTICULA = str(_SCRIPT) if _SCRIPT.exists() else shutil.which("articula")


@pytest.hookimpl(tryfirst=True)  # before `-m` deselects by marker
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """`@pytest.mark.slow_cases(keep=1)`: one case of a parametrized test stays in the default
    step (`keep` first cases, or the cases whose ids `keep` names), the others are marked slow."""
    seen: dict[str, int] = {}
    for item in items:
        mark = item.get_closest_marker("slow_cases")
        if mark is None:
            continue
        keep = mark.kwargs.get("keep", mark.args[0] if mark.args else 1)
        key = item.nodeid.split("[", 1)[0]
        seen[key] = index = seen.get(key, 0)
        seen[key] += 1
        callspec = getattr(item, "callspec", None)
        fast = (
            index < keep if isinstance(keep, int) else callspec is not None and callspec.id in keep
        )
        if not fast:
            item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="session")
def articula_script() -> str:
    """Path of the installed `articula` console script."""
    assert ARTICULA is not None, "the articula console script is not installed"
    return ARTICULA


@pytest.fixture(scope="session", autouse=True)
def decomposition_cache(tmp_path_factory) -> Path:
    """Convex decompositions cached in a folder of the test session, not the user's cache
    (the console scripts the tests run inherit it)."""
    folder = tmp_path_factory.mktemp("decompositions")
    os.environ["ARTICULA_CACHE_DIR"] = str(folder)
    return folder


@pytest.fixture
def tiny_config() -> dict[str, Any]:
    """A motor.current config that simulates in milliseconds (200 steps)."""
    return {"experiment": "motor.current", "duration": 0.2, "settle": 0.1}


@pytest.fixture
def write_toml(tmp_path: Path) -> Callable[..., Path]:
    """write_toml(data, name="x.toml", where=tmp_path) -> path of the written TOML file."""

    def write(
        data: Mapping[str, Any], name: str = "config.toml", where: Path | None = None
    ) -> Path:
        path = (where or tmp_path) / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(tomli_w.dumps(dict(data)))
        return path

    return write


@pytest.fixture(scope="session")
def cli() -> Callable[..., subprocess.CompletedProcess[str]]:
    """cli(*args, cwd=None, env=None) runs the real `articula` console script, capturing output.

    `env` holds extra environment variables laid over the current environment.
    """
    assert ARTICULA is not None, "the articula console script is not installed"

    def run(
        *args: Any,
        cwd: Path | None = None,
        env: Mapping[str, str] | None = None,
        timeout: float = 600,
    ) -> subprocess.CompletedProcess:
        return subprocess.run(
            [ARTICULA, *map(str, args)],
            capture_output=True,
            text=True,
            cwd=cwd,
            env={**os.environ, **env} if env else None,
            timeout=timeout,
            check=False,
        )

    return run


@pytest.fixture(scope="session")
def assert_one_line_error() -> Callable[..., str]:
    """Check a failed CLI call: exit status 2, exactly one non-empty stderr line, no traceback.

    Returns the stderr line. `names` are substrings the line must contain (the field at fault).
    """

    def check(proc: subprocess.CompletedProcess, *names: str) -> str:
        lines = proc.stderr.splitlines()
        assert proc.returncode == 2, (proc.returncode, proc.stderr)
        assert len(lines) == 1, proc.stderr
        line = lines[0]
        assert line.strip(), proc.stderr
        assert "Traceback" not in proc.stderr
        for name in names:
            assert name in line, (name, line)
        return line

    return check


@pytest.fixture(scope="session")
def one_json() -> Callable[[str], dict[str, Any]]:
    """one_json(stdout) -> the single JSON object that stdout holds, with nothing else around it."""

    def parse(stdout: str) -> dict[str, Any]:
        text = stdout.strip()
        obj, end = json.JSONDecoder().raw_decode(text)
        assert end == len(text), f"more than one JSON value on stdout: {stdout!r}"
        assert isinstance(obj, dict), stdout
        return obj

    return parse


@pytest.fixture
def main_fails(capsys) -> Callable[..., str]:
    """main_fails(*args) runs `articula.cli.main` in-process (the console script's code path,
    without its start-up cost) and checks: SystemExit(2), nothing on stdout, one stderr line,
    no traceback. Returns that line."""
    from articula.cli import main

    def run(*args: Any) -> str:
        with pytest.raises(SystemExit) as exc:
            main([str(a) for a in args])
        assert exc.value.code == 2
        captured = capsys.readouterr()
        assert captured.out == ""
        lines = captured.err.splitlines()
        assert len(lines) == 1 and lines[0].strip(), captured.err
        assert "Traceback" not in captured.err
        return lines[0]

    return run


@pytest.fixture
def emulate_process() -> Iterator[Callable[..., tuple[subprocess.Popen, str]]]:
    """emulate_process(rig, *args): `articula emulate RIG <args>` as a process, and the device
    path of its first line; every process is stopped (SIGTERM, then SIGKILL) after."""
    started: list[subprocess.Popen] = []

    def run(rig: str, *args: object) -> tuple[subprocess.Popen, str]:
        proc = subprocess.Popen([ARTICULA, "emulate", rig, *map(str, args)],
                                stdout=subprocess.PIPE, text=True)  # fmt: skip
        started.append(proc)
        line = proc.stdout.readline()  # "RIG rig at /dev/pts/N (Ctrl-C stops it)"
        assert " rig at " in line, f"emulate printed {line!r}, exit {proc.poll()}"
        return proc, line.split()[3]

    yield run
    for proc in started:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(10)
