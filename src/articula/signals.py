"""A long-running command (a viewer, a live loop, an emulated rig, a drive) stopped by SIGTERM
as by Ctrl-C: the same clean end (a live session's --record written, a firmware harness
stopped), then the signal's own exit status (the CLI's: 143 for SIGTERM, 130 for Ctrl-C) and a
plain line (not the one of a sweep, whose finished runs resume)."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType


class Terminated(BaseException):
    """SIGTERM, raised where the command's Ctrl-C would be (not a KeyboardInterrupt: click
    would turn that into Ctrl-C's status)."""


class Interrupted(BaseException):
    """Ctrl-C that ended a long-running command, once the command has ended cleanly (not a
    KeyboardInterrupt: click would turn that into a bare exit status, and the CLI would print
    the line of a sweep's Ctrl-C)."""


@contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM raises Terminated in the main thread; a KeyboardInterrupt
    that leaves the block leaves it as Interrupted.

    Yields:
        Nothing; the previous SIGTERM handler is back after the block.
    """

    def raise_terminated(signum: int, frame: FrameType | None) -> None:
        raise Terminated

    previous = signal.signal(signal.SIGTERM, raise_terminated)
    try:
        yield
    except KeyboardInterrupt as exc:
        raise Interrupted from exc
    finally:
        signal.signal(signal.SIGTERM, previous)
