"""The primary and secondary interfaces (ports 30001–30003) as far as a program goes: a client
writes a URScript program, `def name():` to an `end` at the start of a line, and the
controller runs it at once (the interfaces' robot-state messages are not sent)."""

from __future__ import annotations

import re
import socket

from articula.arms.ur_fake.controller import Controller
from articula.arms.ur_fake.program import parse_program

__all__ = ["serve_script"]

_DEF = re.compile(r"def (\w+)\(\):")


def serve_script(conn: socket.socket, controller: Controller) -> None:
    """Run each program a client sends, until it hangs up.

    Args:
        conn: the accepted socket.
        controller: the controller the programs run on.
    """
    pending = ""
    with conn:
        while chunk := conn.recv(65536):
            pending += chunk.decode("utf-8", "replace")
            while (end := _program_end(pending)) is not None:
                text, pending = pending[:end], pending[end:]
                found = _DEF.search(text)
                name = found.group(1) if found else "<unnamed>"
                with controller.lock:
                    controller.run_program(parse_program(text.lstrip()), name)


def _program_end(text: str) -> int | None:
    """Where the first whole program in `text` ends (after its closing `end` line)."""
    found = re.search(r"^end[ \t]*(\r?\n|$)", text, re.MULTILINE)
    if found is None or not found.group(1):
        return None
    return found.end()
