"""A long-running command (a viewer, a live loop, an emulated rig) stopped by SIGTERM as by
Ctrl-C: the same clean end (a live session's --record written, a firmware harness stopped),
then the signal's own exit status (the CLI's: 143 for SIGTERM, 130 for Ctrl-C)."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType


class Terminated(BaseException):
    """SIGTERM, raised where the command's Ctrl-C would be (not a KeyboardInterrupt: click
    would turn that into Ctrl-C's status)."""


@contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM raises Terminated in the main thread.

    Yields:
        Nothing; the previous SIGTERM handler is back after the block.
    """

    def raise_terminated(signum: int, frame: FrameType | None) -> None:
        raise Terminated

    previous = signal.signal(signal.SIGTERM, raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
