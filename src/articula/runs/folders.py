"""Output folders: checked before any work, claimed by one process at a time.

A folder articula writes into is either new, empty, or one it wrote before (a run folder, a
sweep folder, a report folder): anything else is refused unless the caller forces it, and even
then only articula's own files in it are replaced. While a process writes, it holds an
exclusive `flock` on the folder itself, so a second writer is refused with the holder's pid
and command; the kernel drops the lock when the holder dies, however it dies, so no stale lock
is ever left behind. Temporary files named the way `records.atomic_write` names them are
removed only by the lock holder, so an in-flight file of another writer is never touched.
"""

from __future__ import annotations

import errno
import fcntl
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Literal

from articula.errors import ConfigError, ResourceError

Kind = Literal["run", "sweep", "report", "suite", "identification"]
CONFIG = "config.toml"
RECORD = "record.json"
TRACE = "trace.parquet"
RESULTS = "results.parquet"
REPORT = "report.md"
SUMMARY = "summary.json"
SUITE_FILES = frozenset({RESULTS, SUMMARY})  # and the problems/ folder
JOURNAL = "telemetry.csv"  # a rig run's samples as they arrived (rigs/recorder.py)
TUNING = "tuning.json"  # a rig tuning's result (articula rig tune)
TUNED = "tuned.toml"  # a pneunet.pid config of the tuned gains (articula rig tune)
IDENTIFICATION = "identification.json"  # a fit's constants (articula identify)
IDENTIFICATION_FILES = frozenset({IDENTIFICATION, "plant.toml", "fit.png"})
EXCITATION = re.compile(r"^excitation_\d+$")  # a rig identification's recordings, run folders
SERVO = "servo.parquet"  # a plan's servo stream (articula plan --servo-rate)
TABLES = frozenset({SERVO})  # the further tables a run may write beside trace.parquet
RUN_FILES = frozenset({CONFIG, RECORD, TRACE, JOURNAL, TUNING, TUNED}) | TABLES
RUN_FOLDER = re.compile(r"^[0-9a-f]{12}$")  # a sweep's run folder: the config's hash
# What atomic_write leaves when killed mid-write: .<name>.<8 random characters>.tmp
TEMPORARY = re.compile(r"^\.(?P<name>.+)\.[A-Za-z0-9_]{8}\.tmp$")


def temporary_name_of(entry: str) -> str | None:
    """The file a temporary file of atomic_write was to become, or None if `entry` is not one.

    Args:
        entry: a name in a folder (no directory part).

    Returns:
        The name of the file it was to become, or None.
    """
    match = TEMPORARY.match(entry)
    return match.group("name") if match else None


def foreign_entries(folder: Path, kind: Kind) -> list[str]:
    """Names in `folder` that articula would not have written there, sorted.

    Args:
        folder: an existing output folder.
        kind: what articula writes there: "run", "sweep", "report", "suite" or
            "identification".

    Returns:
        The foreign entry names, sorted; empty when everything in it is articula's.
    """
    foreign = []
    for entry in sorted(os.listdir(folder)):
        name = temporary_name_of(entry) or entry
        path = folder / entry
        if kind == "run":
            ours = name in RUN_FILES and not path.is_dir()
        elif kind == "sweep":
            ours = (name == RESULTS and not path.is_dir()) or (
                RUN_FOLDER.match(entry) is not None
                and path.is_dir()
                and not foreign_entries(path, "run")
            )
        elif kind == "identification":
            ours = (name in IDENTIFICATION_FILES and not path.is_dir()) or (
                EXCITATION.match(entry) is not None
                and path.is_dir()
                and not foreign_entries(path, "run")
            )
        elif kind == "suite":
            ours = (name in SUITE_FILES and not path.is_dir()) or (
                entry == "problems" and path.is_dir()
            )
        else:  # a report: report.md and one folder per chapter
            ours = (name == REPORT and not path.is_dir()) or (
                re.fullmatch(r"ch\d+", entry) is not None and path.is_dir()
            )
        if not ours:
            foreign.append(entry)
    return foreign


def check_out(folder: Path, kind: Kind, force: bool = False, option: str = "--out") -> None:
    """ConfigError unless `folder` can take articula's output: absent (with a creatable
    path), an empty folder, or one articula wrote (`force` accepts any folder).

    Args:
        folder: the output folder.
        kind: what articula writes there: "run", "sweep", "report", "suite" or
            "identification".
        force: accept a folder holding files articula did not write.
        option: the command-line option that named the folder, for the message.
    """
    if folder.exists() and not folder.is_dir():
        raise ConfigError(option, f"{_shown(folder)} is a file; give a folder path")
    if not folder.exists():
        parent = next((p for p in folder.parents if p.exists()), None)
        if parent is not None and not parent.is_dir():
            raise ConfigError(
                option,
                f"{_shown(parent)} is a file, so {_shown(folder)} cannot "
                "be created; give a folder path",
            )
        return
    if force:
        return
    foreign = foreign_entries(folder, kind)
    if foreign:
        shown = ", ".join(_shown(Path(f)) for f in foreign[:3]) + (
            " ..." if len(foreign) > 3 else ""
        )
        raise ConfigError(
            option,
            f"{_shown(folder)} holds files articula did not write ({shown}); give a new or "
            "empty folder, or pass --force to write into it (only articula's own files are "
            "replaced)",
        )


@contextmanager
def claimed(folder: Path, kind: Kind, force: bool = False) -> Iterator[Path]:
    """Create `folder` if needed, check it (see check_out), hold its lock while the body runs,
    and first remove the temporary files a killed writer left there.

    Args:
        folder: the output folder (--out).
        kind: what articula writes there: "run", "sweep", "report", "suite" or
            "identification".
        force: accept a folder holding files articula did not write.

    Yields:
        `folder`, created and locked by this process.
    """
    check_out(folder, kind, force)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except OSError as exc:
        raise ConfigError("--out", f"cannot create {_shown(folder)} ({exc.strerror})") from None
    try:
        _lock(fd, folder)
        check_out(folder, kind, force)  # again: another writer may have been faster
        remove_stale_temporaries(folder, kind)
        yield folder
    finally:
        os.close(fd)  # releases the lock


def remove_stale_temporaries(folder: Path, kind: Kind) -> None:
    """Remove atomic_write's temporary files of articula's own files in `folder` (and in its
    run folders, for a sweep). Only the lock holder may call this.

    Args:
        folder: the output folder, locked by this process.
        kind: what articula writes there: "run", "sweep", "report", "suite" or
            "identification".
    """
    own = {
        "run": RUN_FILES,
        "sweep": {RESULTS},
        "report": {REPORT},
        "suite": SUITE_FILES,
        "identification": IDENTIFICATION_FILES,
    }[kind]
    for entry in os.listdir(folder):
        if temporary_name_of(entry) in own:
            (folder / entry).unlink(missing_ok=True)
        elif kind == "sweep" and RUN_FOLDER.match(entry) and (folder / entry).is_dir():
            remove_stale_temporaries(folder / entry, "run")


def _lock(fd: int, folder: Path) -> None:
    """Take the folder's exclusive lock without waiting; ResourceError naming the holder."""
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN):
            raise
        raise ResourceError(
            f"--out: {_shown(folder)} is being written by another process ({holder(folder)}); "
            "wait for it to finish or choose another folder"
        ) from None


def holder(folder: Path) -> str:
    """Who holds the lock of `folder`: "pid N: its command line", as far as /proc tells.

    Args:
        folder: a locked output folder.

    Returns:
        "pid N: its command line", or "unknown" when /proc does not tell.
    """
    st = folder.stat()
    device = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}:{st.st_ino}"
    try:
        with open("/proc/locks", encoding="ascii") as locks:
            pids = [line.split()[4] for line in locks if line.split()[5:6] == [device]]
        if not pids:
            return "unknown"
        command = Path(f"/proc/{pids[0]}/cmdline").read_bytes().replace(b"\0", b" ").strip()
        return f"pid {pids[0]}: {command.decode(errors='replace')}"
    except (OSError, IndexError):
        return "unknown"


def _shown(path: Path) -> str:
    """A path for a one-line message: control characters (a newline in a name) escaped."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(path))
