"""Output that native libraries print, caught at the file-descriptor level.

Pinocchio's URDF parser writes warnings straight to the process's stdout and stderr, past
Python's sys.stdout; a command that promises one line of output has to catch them there.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def captured_output() -> Iterator[list[str]]:
    """Send what is written to fds 1 and 2 inside the block to a buffer; the yielded list gets
    its lines (stripped, non-empty) when the block ends.

    Yields:
        The list that receives the captured lines once the block has ended.
    """
    lines: list[str] = []
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            sink.seek(0)
            text = sink.read().decode(errors="replace")
            lines.extend(line.strip() for line in text.splitlines() if line.strip())
