"""The --rt-priority option of the commands that stream to an arm or keep a rig's line."""

from __future__ import annotations

from typing import Annotated

import typer

RtPriority = Annotated[
    int | None,
    typer.Option(
        help="Run under real-time scheduling (SCHED_FIFO) at this priority, 1-99, so that a "
        "busy host cannot starve the line or the stream (needs root or CAP_SYS_NICE).",
    ),
]


def use_realtime(priority: int | None) -> None:
    """Real-time scheduling for this process from now on (arms.realtime), if asked for.

    Args:
        priority: the SCHED_FIFO priority (1-99); None: ordinary scheduling.
    """
    if priority is not None:
        from articula.arms.realtime import use_realtime as switch

        switch(priority)
