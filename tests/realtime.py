"""Real-time scheduling in tests: where the machine allows SCHED_FIFO (root or CAP_SYS_NICE),
a test that streams to an arm or keeps a rig's heartbeat runs its process under it, as a
servo or bench host should run, so that other work on a loaded machine cannot starve it."""

from __future__ import annotations

import contextlib
import subprocess
import sys
from collections.abc import Iterator
from functools import cache

from articula.arms.realtime import use_ordinary, use_realtime

DRIVE_PRIORITY = 10  # SCHED_FIFO priority of a test's own stream or rig host


@cache
def realtime_allowed() -> bool:
    """Whether processes here may use SCHED_FIFO (asked of a child process)."""
    ask = "import os; os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))"
    child = subprocess.run([sys.executable, "-c", ask], capture_output=True)
    return child.returncode == 0


@contextlib.contextmanager
def realtime_here(priority: int = DRIVE_PRIORITY) -> Iterator[None]:
    """This test process under SCHED_FIFO within the block (where allowed), for a servo
    stream or a rig's line served from the test itself; ordinary scheduling after it."""
    if not realtime_allowed():
        yield
        return
    use_realtime(priority)
    try:
        yield
    finally:
        use_ordinary()
