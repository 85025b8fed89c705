"""`articula` command line: parses, calls the library, prints. Errors are one line.

Exit status: 0 done; 2 bad input (the line names the field or option and the fix); 1 the
machine stopped the work (disk full, folder in use, I/O error, out of memory); 3 a bug of
articula's (the line says so; ARTICULA_DEBUG=1 shows the traceback); 4 a planned motion
collides (its run folder is written); 130 interrupted (Ctrl-C); 143 terminated (SIGTERM: a
viewer, live loop or emulated rig ends as on Ctrl-C).
"""

from __future__ import annotations

import errno
import os
import sys
import warnings
from typing import NoReturn

import typer
from typer.exceptions import Abort, Exit, TyperException

from articula.cli import (  # noqa: F401  (each module adds its commands to app)
    arm,
    bench,
    book,
    drive,
    emulate,
    identify,
    rig_tune,
    rigs,
    runs,
    scene,
    viewer,
)
from articula.cli.app import app
from articula.cli.words import speak_in_words
from articula.errors import ArticulaError, CollisionError, DeviceError, ResourceError
from articula.signals import Interrupted, Terminated

BAD_INPUT, ENVIRONMENT, BUG, COLLIDES, INTERRUPTED, TERMINATED = 2, 1, 3, 4, 130, 143
# OS errors that the machine causes; every other OSError is about a path the user gave.
MACHINE_ERRNOS = {
    errno.ENOSPC,
    errno.EDQUOT,
    errno.EIO,
    errno.EBUSY,
    errno.ENOMEM,
    errno.EMFILE,
    errno.ENFILE,
    errno.ETXTBSY,
}


def main(argv: list[str] | None = None) -> None:
    """Entry point: run the app; every failure becomes one line on stderr and its exit status."""
    debug = bool(os.environ.get("ARTICULA_DEBUG"))
    with warnings.catch_warnings(record=not debug) as caught:
        try:
            # Typer turns a Ctrl-C inside a command into Exit(130), which this mode returns.
            if _command()(args=argv, standalone_mode=False) == INTERRUPTED:
                raise KeyboardInterrupt
        except Exit as exc:
            sys.exit(exc.exit_code)
        except Exception as exc:  # every failure, ours or not, ends here as one line
            if debug:
                raise
            _fail(*_status_and_message(exc))
        except Terminated:  # a server, a live loop, an emulated rig or a drive
            _fail(TERMINATED, "terminated (SIGTERM)")
        except Interrupted:  # the same, on Ctrl-C
            _fail(INTERRUPTED, "interrupted (Ctrl-C)")
        except KeyboardInterrupt:
            _fail(
                INTERRUPTED,
                "interrupted (Ctrl-C); finished work is kept: a sweep resumes, a "
                "rig run's folder says it is incomplete",
            )
    if caught:
        first = f"{_one_line(str(caught[0].message))} ({caught[0].category.__name__})"
        sys.stderr.write(f"warning: {len(caught)} warning(s), the first: {first}\n")


def _command() -> typer.core.TyperGroup:
    """The app as a click command whose help names option types in words."""
    command = typer.main.get_command(app)
    speak_in_words(command, typer.Context(command))
    return command


def _status_and_message(exc: Exception) -> tuple[int, str]:
    """The exit status and one-line message of a failure."""
    if isinstance(exc, (ResourceError, DeviceError)):
        return ENVIRONMENT, str(exc)
    if isinstance(exc, CollisionError):
        return COLLIDES, str(exc)
    if isinstance(exc, ArticulaError):
        return BAD_INPUT, str(exc)
    if isinstance(exc, Abort):
        return BAD_INPUT, "aborted"
    if isinstance(exc, TyperException):
        return BAD_INPUT, " ".join(exc.format_message().split()) or "missing command; see --help"
    if isinstance(exc, MemoryError):
        return ENVIRONMENT, "out of memory; run a smaller config or free memory"
    if isinstance(exc, OSError):
        where = f"{exc.filename}: " if exc.filename else ""
        reason = exc.strerror or str(exc)
        if exc.errno in MACHINE_ERRNOS:
            return ENVIRONMENT, f"{where}{reason}"
        return BAD_INPUT, f"{where}{reason}; check the path and its permissions"
    if isinstance(exc, (OverflowError, FloatingPointError)):
        return BAD_INPUT, f"a number is too large to compute with ({exc}); check the inputs"
    return BUG, (
        f"internal error ({type(exc).__name__}: {exc}); please report it with the "
        "command (ARTICULA_DEBUG=1 shows the traceback)"
    )


def _one_line(text: str) -> str:
    """`text` with its line breaks escaped, so that a message stays one line."""
    return text.replace("\r", "\\r").replace("\n", "\\n")


def _fail(status: int, message: str) -> NoReturn:
    sys.stderr.write(f"error: {_one_line(message)}\n")
    sys.exit(status)
