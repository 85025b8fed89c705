"""`articula` command line: parses, calls the library, prints. Errors are one line, exit 2."""

from __future__ import annotations

import sys

from typer.exceptions import Abort, Exit, TyperException

from articula.cli import arm, book, runs  # noqa: F401  (each module adds its commands to app)
from articula.cli.app import app
from articula.errors import ArticulaError


def main(argv: list[str] | None = None) -> None:
    """Entry point: run the app; any bad input becomes one line on stderr and exit status 2."""
    try:
        app(args=argv, standalone_mode=False)
    except ArticulaError as exc:
        _fail(str(exc))
    except Exit as exc:
        sys.exit(exc.exit_code)
    except Abort:
        _fail("aborted")
    except TyperException as exc:
        message = exc.format_message().replace("\n", " ").strip()
        _fail(message or "missing command; see --help")


def _fail(message: str) -> None:
    sys.stderr.write(f"error: {message}\n")
    sys.exit(2)
