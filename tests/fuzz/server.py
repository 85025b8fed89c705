"""A fork server for the CLI fuzzer: import articula once, run every command in a fresh child.

Started once per test session (`python tests/fuzz/server.py`), it imports `articula.cli` and
the heavy modules behind it, then answers requests, one JSON object per line on stdin and one
per line on stdout. Each `run` request forks a child that applies a memory limit
(RLIMIT_AS) and a CPU limit (RLIMIT_CPU), sends its stdout and stderr to files, changes to the
request's folder and calls `articula.cli.main(args)`, so a segfault, a runaway allocation or a
hang ends the child, never the server, at a few milliseconds per example instead of the
interpreter's one to three seconds of start-up.

Requests (one JSON object per line):

    {"op": "run", "args": [...], "cwd": "...", "env": {...}, "timeout": 60,
     "memory": 4294967296, "max_processes": 32, "probe": null}
    {"op": "warm", "args": [...], "cwd": "..."}   run main(args) in the server itself, so that
        compiled (numba) code is loaded once and every child inherits it
    {"op": "threads"}                               the server's thread count
    {"op": "quit"}

`probe` (test-only) replaces the command by a known behaviour of the child: "segfault",
"sleep" (for `seconds`), "allocate" (`bytes`) or "raise". Answers to `run`:

    {"status": int | null, "signal": int | null, "timed_out": bool, "wall": seconds,
     "processes": int, "too_many_processes": bool, "stdout": str, "stderr": str,
     "maxrss_kb": int, "leftover": bool}

`status` is the exit status (SystemExit's code; 99 after an uncaught exception, whose
traceback goes to stderr); `signal` the number of the signal that killed the child;
`processes` the largest size of the child's process group seen (counted every 20 ms; over
`max_processes` the group is killed, since RLIMIT_NPROC does not bind root); `leftover` tells
that processes of the child's process group outlived it (they are killed). The server is the
subreaper of its children's orphans, so none is left as a zombie.

The server stays single-threaded, since forking a process with threads can deadlock the
child: it refuses to fork when /proc/self/task lists more than one thread. Thread pools are
kept from starting by the environment the client sets (OPENBLAS_NUM_THREADS=1,
JE_ARROW_MALLOC_CONF=background_thread:false, ...; see `SERVER_ENV`).
"""

from __future__ import annotations

import contextlib
import json
import os
import resource
import select
import signal
import sys
import tempfile
import time
import traceback
from typing import Any

# Keep native thread pools from starting: they would make fork unsafe.
SERVER_ENV = {
    "OPENBLAS_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "NUMBA_NUM_THREADS": "1",
    "JE_ARROW_MALLOC_CONF": "background_thread:false",  # pyarrow's jemalloc
    "PYTHONUNBUFFERED": "1",
    "NO_COLOR": "1",
    "COLUMNS": "120",
}
GIB = 1 << 30
DEFAULT_MEMORY = 4 * GIB  # [bytes] RLIMIT_AS of a child
CPU_SLACK = 5  # [s] RLIMIT_CPU = timeout + this
MAX_OUTPUT = 1 << 20  # [bytes] of stdout or stderr sent back; the rest is cut
# Processes a child's process group may hold (itself, pool workers, ...) before it is killed:
# RLIMIT_NPROC does not bind root, and a runaway pool must not exhaust the machine's PIDs.
MAX_PROCESSES = 32
POLL_SECONDS = 0.02  # [s] between two counts of a child's processes
# Modules imported before serving (articula.cli imports its commands' modules lazily).
PRELOAD = (
    "numpy",
    "scipy",
    "numba",
    "pyarrow",
    "pyarrow.parquet",
    "pinocchio",
    "coal",
    "trimesh",
    "articula.cli",
    "articula.runs.runner",
    "articula.runs.sweep",
    "articula.runs.records",
    "articula.scene.check",
    "articula.experiments.plan",
    "articula.experiments.pneunet",
    "articula.experiments.six_chamber",
    "articula.experiments.motor",
    "articula.book.ch4.motor_analysis",
    "articula.book.reproduce",
)


def thread_count() -> int:
    """Threads of this process."""
    return len(os.listdir("/proc/self/task"))


def _preload() -> list[str]:
    """Import PRELOAD; returns the modules that failed, with their error."""
    import importlib

    failed = []
    for name in PRELOAD:
        try:
            importlib.import_module(name)
        except Exception as exc:  # reported to the client, which decides
            failed.append(f"{name}: {type(exc).__name__}: {exc}")
    return failed


def _status_of(exc: SystemExit) -> int:
    """The exit status the interpreter would give for SystemExit(code)."""
    code = exc.code
    if code is None:
        return 0
    if isinstance(code, int):
        return code & 0xFF
    sys.stderr.write(f"{code}\n")
    return 1


def _call_main(args: list[str]) -> int:
    """articula.cli.main(args) as a process would end it: its exit status."""
    from articula.cli import main

    try:
        main(args)
    except SystemExit as exc:
        return _status_of(exc)
    except BaseException:
        traceback.print_exc()
        return 99
    return 0


def _probe(request: dict[str, Any]) -> int:
    """Test-only behaviours of a child, to test the harness itself."""
    kind = request["probe"]
    if kind == "segfault":
        os.kill(os.getpid(), signal.SIGSEGV)
    elif kind == "sleep":
        time.sleep(float(request.get("seconds", 3600)))
    elif kind == "allocate":
        block = bytearray(int(request["bytes"]))  # noqa: F841 (held until exit)
    elif kind == "raise":
        raise RuntimeError("probe")
    elif kind == "spawn":  # grandchildren in the child's process group, left running
        for _ in range(int(request.get("count", 1))):
            if os.fork() == 0:
                time.sleep(3600)
                os._exit(0)
        time.sleep(float(request.get("seconds", 0)))
    return 0


def _child(request: dict[str, Any], out_path: str, err_path: str, private: list[int]) -> None:
    """The forked child: limits, redirections, folder, then the command; never returns."""
    status = 98
    try:
        os.setpgid(0, 0)
        for fd in private:
            os.close(fd)
        os.close(0)
        null = os.open(os.devnull, os.O_RDONLY)  # never the server's request pipe
        if null != 0:
            os.dup2(null, 0)
            os.close(null)
        for fd, path in ((1, out_path), (2, err_path)):
            target = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
            os.dup2(target, fd)
            os.close(target)
        memory = int(request.get("memory") or DEFAULT_MEMORY)
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
        cpu = int(float(request.get("timeout", 60)) + CPU_SLACK)
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
        os.environ.update(request.get("env") or {})
        os.chdir(request.get("cwd") or os.getcwd())
        import faulthandler

        faulthandler.enable(file=sys.stderr)  # a native crash shows the Python line at fault
        if request.get("probe"):
            status = _probe(request)
        else:
            status = _call_main([str(a) for a in request["args"]])
    except SystemExit as exc:
        status = _status_of(exc)
    except BaseException:
        try:
            traceback.print_exc()
        finally:
            status = 99
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(status)


def _read(path: str) -> str:
    with open(path, "rb") as f:
        data = f.read(MAX_OUTPUT + 1)
    text = data[:MAX_OUTPUT].decode("utf-8", errors="replace")
    return text + ("\n[output cut by the fuzz server]" if len(data) > MAX_OUTPUT else "")


def group_size(pgid: int) -> int:
    """Processes (zombies excluded) whose process group is `pgid`."""
    count = 0
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as f:
                fields = f.read().rsplit(b")", 1)[1].split()
        except OSError:
            continue  # ended meanwhile
        if fields[0] != b"Z" and int(fields[2]) == pgid:
            count += 1
    return count


def _wait(pid: int, timeout: float, max_processes: int) -> tuple[int, Any, bool, int]:
    """Wait for the child up to `timeout` [s], killing its process group after it or as soon
    as the group holds more than `max_processes` processes.
    Returns (wait status, rusage, timed out, largest group size seen)."""
    deadline = time.monotonic() + max(timeout, 0.0)
    largest = 1
    pidfd = os.pidfd_open(pid)
    try:
        poller = select.poll()
        poller.register(pidfd, select.POLLIN)
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                timed_out = True
                break
            if poller.poll(min(left, POLL_SECONDS) * 1000):
                timed_out = False
                break
            largest = max(largest, group_size(pid))
            if largest > max_processes:
                timed_out = False
                break
    finally:
        os.close(pidfd)
    if timed_out or largest > max_processes:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(pid, signal.SIGKILL)  # the rest of the group: _kill_group, once reaped
    _, wait_status, usage = os.wait4(pid, 0)
    return wait_status, usage, timed_out, largest


def _kill_group(pgid: int) -> bool:
    """SIGKILL every process of a process group until none is left, reaping them (call it
    after its leader was waited for); True if there was one."""
    found = False
    for _ in range(100):
        try:
            os.killpg(pgid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            return found
        found = True
        _reap()
        time.sleep(0.01)
    return found


def _reap() -> None:
    """Collect orphaned grandchildren (the server is their subreaper)."""
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return


def _become_subreaper() -> None:
    """Orphans of the children come to the server (which reaps them), not to init."""
    import ctypes

    PR_SET_CHILD_SUBREAPER = 36
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)


def run(request: dict[str, Any], private: list[int], scratch: str) -> dict[str, Any]:
    """Fork a child for one request and report how it ended."""
    threads = thread_count()
    if threads != 1:
        return {"error": f"the fuzz server has {threads} threads; it forks only when it has one"}
    out_path = os.path.join(scratch, "stdout")
    err_path = os.path.join(scratch, "stderr")
    sys.stdout.flush()
    sys.stderr.flush()
    start = time.monotonic()
    pid = os.fork()
    if pid == 0:
        _child(request, out_path, err_path, private)
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.setpgid(pid, pid)  # also done by the child; whichever runs first wins the race
    max_processes = int(request.get("max_processes") or MAX_PROCESSES)
    wait_status, usage, timed_out, largest = _wait(
        pid, float(request.get("timeout", 60)), max_processes
    )
    wall = time.monotonic() - start
    leftover = _kill_group(pid)  # the group outlived its leader: pool workers, grandchildren
    killed = os.WIFSIGNALED(wait_status)
    return {
        "status": None if killed else os.WEXITSTATUS(wait_status),
        "signal": os.WTERMSIG(wait_status) if killed else None,
        "timed_out": timed_out,
        "processes": largest,
        "too_many_processes": largest > max_processes,
        "wall": wall,
        "stdout": _read(out_path),
        "stderr": _read(err_path),
        "maxrss_kb": usage.ru_maxrss,
        "leftover": leftover,
    }


def warm(request: dict[str, Any]) -> dict[str, Any]:
    """Run a command in the server itself (output discarded), to load compiled code once."""
    saved = os.dup(1), os.dup(2)
    null = os.open(os.devnull, os.O_WRONLY)
    cwd = os.getcwd()
    signal.alarm(int(request.get("timeout", 300)))
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        os.chdir(request.get("cwd") or cwd)
        status = _call_main([str(a) for a in request["args"]])
    finally:
        signal.alarm(0)
        sys.stdout.flush()
        sys.stderr.flush()
        os.chdir(cwd)
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)
    return {"status": status, "threads": thread_count()}


def _on_alarm(signum: int, frame: Any) -> None:
    raise TimeoutError("warm-up command took too long")


def serve() -> None:
    """Answer requests from stdin until it closes or a `quit` request comes."""
    for key, value in SERVER_ENV.items():
        os.environ.setdefault(key, value)
    # Answers go to a private copy of stdout; fd 1 then points at stderr, so that whatever
    # an import prints cannot corrupt the protocol.
    answers = os.fdopen(os.dup(1), "w", buffering=1, encoding="utf-8")
    os.dup2(2, 1)
    requests = sys.stdin.buffer
    signal.signal(signal.SIGALRM, _on_alarm)
    _become_subreaper()
    failed = _preload()
    answers.write(json.dumps({"ready": True, "failed": failed, "pid": os.getpid()}) + "\n")
    private = [answers.fileno()]
    with tempfile.TemporaryDirectory(prefix="articula-fuzz-server-") as scratch:
        for line in requests:
            if not line.strip():
                continue
            request = json.loads(line)
            op = request.get("op", "run")
            try:
                if op == "quit":
                    break
                if op == "threads":
                    answer: dict[str, Any] = {"threads": thread_count()}
                elif op == "warm":
                    answer = warm(request)
                else:
                    answer = run(request, private, scratch)
            except Exception:
                answer = {"error": traceback.format_exc()}
            answers.write(json.dumps(answer) + "\n")


if __name__ == "__main__":
    serve()
