"""Keep numba's on-disk cache consistent with the sources it was compiled from.

numba keys a cached function on its own file only, so a compiled function that calls a
compiled function in another module keeps the callee's old code after that module changes
(e.g. after `git pull` in an editable install). Before any compiled code loads, the package's
cache files are removed whenever its compiled sources differ from those they were built from.
Compiled modules decorate with `jit(...)`, which does that check once per process, when the
first compiled module is imported: `import articula` alone reads no source file.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any

import numba

PACKAGE = Path(__file__).resolve().parent
STAMP = "numba-sources.sha256"


def sources_digest(root: Path) -> str:
    """SHA-256 over every module under `root` that uses numba (path and bytes).

    Args:
        root: the package folder to scan.

    Returns:
        The hexadecimal digest.
    """
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        data = path.read_bytes()
        if b"numba" in data:
            digest.update(path.relative_to(root).as_posix().encode() + b"\0" + data)
    return digest.hexdigest()


def refresh_cache(root: Path = PACKAGE) -> bool:
    """Delete every cached compilation under `root` if its numba sources changed since the
    last call; returns True if it did. A read-only install is left as it is.

    Args:
        root: the package folder whose `__pycache__` folders hold numba's cache.

    Returns:
        Whether the cache was cleared (False if it was current or not writable).
    """
    digest = sources_digest(root)
    stamp = root / "__pycache__" / STAMP
    try:
        if stamp.read_text(encoding="ascii") == digest:
            return False
    except OSError:
        pass  # no stamp yet
    try:
        for cached in [*root.rglob("__pycache__/*.nbi"), *root.rglob("__pycache__/*.nbc")]:
            cached.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(digest, encoding="ascii")
    except OSError:
        return False  # not writable: numba then caches in its user-wide folder
    return True


def is_cold(root: Path = PACKAGE) -> bool:
    """Whether the next compiled call compiles from scratch: nothing cached under `root`, or
    its numba sources changed since the cache was built (the next `jit` then clears it).

    Args:
        root: the package folder whose `__pycache__` folders hold numba's cache.

    Returns:
        True if so; False for a cache that is current, or one numba keeps elsewhere (a
        read-only install: nothing here says).
    """
    stamp = root / "__pycache__" / STAMP
    if not os.access(root, os.W_OK):
        return False
    try:
        current = stamp.read_text(encoding="ascii") == sources_digest(root)
    except OSError:
        current = False
    return not (current and any(root.rglob("__pycache__/*.nbi")))


@cache
def _refresh_once() -> None:
    """refresh_cache() for the installed package, at most once per process."""
    refresh_cache()


def jit(**options: Any) -> Callable[[Callable[..., Any]], Any]:
    """numba.njit with an on-disk cache that never outlives its sources (and `options`).

    Args:
        **options: further options for numba.njit (e.g. `fastmath`, `parallel`).

    Returns:
        The decorator that compiles a function.
    """
    _refresh_once()
    return numba.njit(cache=True, **options)
