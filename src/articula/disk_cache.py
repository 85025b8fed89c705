"""Files articula computes once and keeps: convex decompositions, self-collision matrices."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def cache_folder() -> Path:
    """Where computed files are kept: $ARTICULA_CACHE_DIR, else the user's cache.

    Returns:
        The cache folder (it may not exist yet).
    """
    if "ARTICULA_CACHE_DIR" in os.environ:
        return Path(os.environ["ARTICULA_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "articula" / "decompositions"


def read_cached(name: str) -> bytes | None:
    """A kept file's contents, or None when it is not there or cannot be read.

    Args:
        name: the file's name in the cache folder.

    Returns:
        The bytes written by `keep`, or None.
    """
    try:
        return (cache_folder() / name).read_bytes()
    except OSError:
        return None


def keep(name: str, data: bytes) -> None:
    """Keep a file for next time, written whole or not at all (a read-only home keeps nothing).

    Args:
        name: the file's name in the cache folder.
        data: its contents.
    """
    folder = cache_folder()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".tmp")
    except OSError:
        return
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, folder / name)
    except OSError:
        Path(tmp).unlink(missing_ok=True)
