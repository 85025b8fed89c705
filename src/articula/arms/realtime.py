"""Real-time scheduling for a process that streams to an arm (or plays a controller's cycle).

A servo stream needs the CPU every tick: on a host whose cores are busy with other work an
ordinary thread can wait tens of milliseconds for its turn, and a UR controller's RTDE
watchdog (100 ms here) then stops the program. Under SCHED_FIFO the kernel runs the process's
threads before any ordinary one. Every thread of the process gets the policy, not only the
servo thread: the threads share Python's GIL, and a planner thread preempted while holding it
would keep a real-time servo thread waiting (a priority inversion). Threads started later
inherit the policy from the thread that starts them (Linux, POSIX threads' default).

The process has to be allowed to: root, CAP_SYS_NICE, or an `ulimit -r` of at least the
priority. Linux keeps 5 % of each second for ordinary threads (kernel.sched_rt_runtime_us),
so a real-time process that spins cannot lock the host up.
"""

from __future__ import annotations

import os
from pathlib import Path

from articula.errors import ConfigError

__all__ = ["scheduling", "use_ordinary", "use_realtime"]


def use_realtime(priority: int, option: str = "--rt-priority") -> None:
    """Run every thread of this process, and those it starts later, under SCHED_FIFO.

    Args:
        priority: the real-time priority, 1 (lowest) to 99.
        option: the setting's name, for errors.

    Raises:
        ConfigError: the priority is out of range, the platform has no SCHED_FIFO, or the
            process is not allowed to use it (naming how to allow it).
    """
    if not hasattr(os, "sched_setscheduler"):
        raise ConfigError(option, "real-time scheduling needs Linux (SCHED_FIFO)")
    low, high = os.sched_get_priority_min(os.SCHED_FIFO), os.sched_get_priority_max(os.SCHED_FIFO)
    if not low <= priority <= high:
        raise ConfigError(option, f"must be within [{low}, {high}] (got {priority})")
    param = os.sched_param(priority)
    try:
        for task in Path("/proc/self/task").iterdir():
            try:
                os.sched_setscheduler(int(task.name), os.SCHED_FIFO, param)
            except ProcessLookupError:  # a thread that ended meanwhile
                continue
    except PermissionError:
        raise ConfigError(
            option,
            "this process may not use real-time scheduling: run it as root, give the "
            "interpreter CAP_SYS_NICE (sudo setcap cap_sys_nice+ep $(readlink -f $(which "
            f"python))) or raise `ulimit -r` to {priority}; or leave the option out",
        ) from None


def use_ordinary() -> None:
    """Every thread of this process back under ordinary scheduling (SCHED_OTHER)."""
    if not hasattr(os, "sched_setscheduler"):
        return
    for task in Path("/proc/self/task").iterdir():
        try:
            os.sched_setscheduler(int(task.name), os.SCHED_OTHER, os.sched_param(0))
        except ProcessLookupError:  # a thread that ended meanwhile
            continue


def scheduling() -> str:
    """This thread's scheduling policy, for a run's record.

    Returns:
        "SCHED_FIFO <priority>" under real-time scheduling, "normal" otherwise.
    """
    if not hasattr(os, "sched_getscheduler"):
        return "normal"
    if os.sched_getscheduler(0) == os.SCHED_FIFO:
        return f"SCHED_FIFO {os.sched_getparam(0).sched_priority}"
    return "normal"
