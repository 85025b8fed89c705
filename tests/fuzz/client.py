"""The client of the fork server (tests/fuzz/server.py): start it, send requests, read how
each command ended."""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tests.fuzz.server import DEFAULT_MEMORY, SERVER_ENV

SERVER = Path(__file__).with_name("server.py")
REPO = Path(__file__).resolve().parents[2]
ACCEPT_SECONDS = 60.0  # [s] default time limit of a command; catches hangs
MEMORY = DEFAULT_MEMORY  # [bytes] RLIMIT_AS of every command
START_SECONDS = 300.0  # [s] for the server's imports (and numba's compilations in warm-ups)


class ServerError(RuntimeError):
    """The fork server died, answered garbage or refused a request."""


@dataclass(frozen=True)
class Outcome:
    """How one command ended.

    Attributes:
        status: exit status, or None when a signal killed it.
        signal: number of the signal that killed it, or None.
        timed_out: the server killed it after the request's timeout.
        wall: wall time [s] from fork to exit.
        stdout, stderr: its output (cut at 1 MiB each).
        maxrss_kb: peak resident memory [KiB].
        leftover: processes of its process group outlived it (and were killed).
        processes: the largest number of processes its process group held at once.
        too_many_processes: it was killed for holding more than MAX_PROCESSES.
    """

    status: int | None
    signal: int | None
    timed_out: bool
    wall: float
    stdout: str
    stderr: str
    maxrss_kb: int
    leftover: bool
    processes: int = 1
    too_many_processes: bool = False

    def describe(self) -> str:
        """One line: how it ended."""
        if self.too_many_processes:
            ended = f"killed for running {self.processes} processes at once"
        elif self.timed_out:
            ended = f"killed after the {self.wall:.1f} s time limit"
        elif self.signal is not None:
            ended = f"killed by {signal_name(self.signal)}"
        else:
            ended = f"exit {self.status}"
        return f"{ended} in {self.wall:.2f} s, peak RSS {self.maxrss_kb / 1024:.0f} MiB"


def signal_name(number: int) -> str:
    try:
        return f"{signal.Signals(number).name} ({number})"
    except ValueError:
        return f"signal {number}"


class ForkServer:
    """A running tests/fuzz/server.py and the pipe to it (see that module for the protocol)."""

    def __init__(self, log: Path, env: Mapping[str, str] | None = None) -> None:
        self.log = log
        self._log_file = open(log, "wb")  # noqa: SIM115 (closed in close())
        self.proc = subprocess.Popen(
            [sys.executable, str(SERVER)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._log_file,
            cwd=REPO,
            env={**os.environ, **SERVER_ENV, **(env or {})},
        )
        self._buffer = b""
        hello = self._receive(START_SECONDS)
        if not hello.get("ready"):
            raise ServerError(f"the fuzz server did not start: {hello}")
        self.failed_imports: list[str] = hello["failed"]

    def _send(self, request: Mapping[str, Any]) -> None:
        assert self.proc.stdin is not None
        try:
            self.proc.stdin.write(json.dumps(request).encode() + b"\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            raise ServerError(f"the fuzz server died; its log:\n{self._tail()}") from None

    def _receive(self, timeout: float) -> dict[str, Any]:
        """The next answer line, waiting at most `timeout` [s]."""
        assert self.proc.stdout is not None
        fd = self.proc.stdout.fileno()
        while b"\n" not in self._buffer:
            ready, _, _ = select.select([fd], [], [], timeout)
            if not ready:
                raise ServerError(f"no answer from the fuzz server in {timeout} s")
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                raise ServerError(f"the fuzz server died; its log:\n{self._tail()}")
            self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        answer = json.loads(line)
        if "error" in answer:
            raise ServerError(answer["error"])
        return answer

    def _tail(self) -> str:
        self._log_file.flush()
        return self.log.read_text(errors="replace")[-4000:]

    def request(self, request: Mapping[str, Any], timeout: float) -> dict[str, Any]:
        self._send(request)
        return self._receive(timeout)

    def run(
        self,
        args: Sequence[Any],
        cwd: Path,
        env: Mapping[str, str] | None = None,
        timeout: float = ACCEPT_SECONDS,
        memory: int = MEMORY,
        probe: str | None = None,
        **extra: Any,
    ) -> Outcome:
        """Run `articula ARGS` (or a test-only `probe`) in a fresh child."""
        request = {
            "op": "run", "args": [str(a) for a in args], "cwd": str(cwd), "env": dict(env or {}),
            "timeout": timeout, "memory": memory, "probe": probe, **extra,
        }  # fmt: skip
        answer = self.request(request, timeout + 60)
        return Outcome(**answer)

    def warm(self, args: Sequence[Any], cwd: Path, timeout: float = START_SECONDS) -> int:
        """Run a command inside the server (output discarded); returns its exit status."""
        answer = self.request(
            {"op": "warm", "args": [str(a) for a in args], "cwd": str(cwd), "timeout": timeout},
            timeout + 60,
        )
        return answer["status"]

    def threads(self) -> int:
        return self.request({"op": "threads"}, 30)["threads"]

    def close(self) -> None:
        try:
            self._send({"op": "quit"})
            self.proc.wait(timeout=30)
        except (ServerError, subprocess.TimeoutExpired, OSError):
            self.proc.kill()
            self.proc.wait()
        self._log_file.close()
