"""Run folders: config.toml, record.json, trace.parquet, each written atomically."""

from __future__ import annotations

import hashlib
import json
import math
import os
import platform
import tempfile
from collections.abc import Mapping
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import tomli_w

from articula import __version__
from articula.errors import ConfigError
from articula.runs.folders import CONFIG, RECORD, TABLES, TRACE
from articula.runs.registry import Result

_VERSIONED = (
    "articula", "numpy", "scipy", "numba", "control", "pyarrow", "pydantic",
    "pin", "coal", "trimesh",
)  # fmt: skip


def config_hash(config: Mapping[str, Any]) -> str:
    """Short stable hash of a config mapping and the articula version; names its run folder.

    The version is hashed too, so that a sweep resumed after an upgrade recomputes its runs
    instead of mixing results of two versions of the code.

    Args:
        config: a full config (defaults filled in), with its `experiment` key.

    Returns:
        The first 12 hex digits of the SHA-256 of the config and the articula version.
    """
    payload = {"config": dict(config), "articula": __version__}
    canonical = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()[:12]


def package_versions() -> dict[str, str]:
    """Versions of Python and of the packages that decide the numbers.

    Returns:
        Version strings by name ("python", "numpy", ...); "not installed" for a missing one.
    """
    versions = {"python": platform.python_version()}
    for name in _VERSIONED:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions


def build_record(
    config: Mapping[str, Any], result: Result, wall_time: float, error: str | None = None
) -> dict[str, Any]:
    """The JSON-ready record of one run; `error` says why a run of a sweep could not be done
    (its metrics are then empty).

    Args:
        config: the run's full config, with its `experiment` key.
        result: what the experiment returned; its metrics are recorded (non-finite as null).
        wall_time: the run's wall-clock time [s].
        error: why the run could not be done, or None for a run that was done.

    Returns:
        The record: experiment, seed, config_hash, metrics, versions, wall_time_s, the
        result's details, `tables` (the further files, when there are any) and, for a run
        that could not be done, error.
    """
    record = {
        **result.details,
        "experiment": config["experiment"],
        "seed": config.get("seed"),
        "config_hash": config_hash(config),
        "metrics": {k: _json_number(v) for k, v in result.metrics.items()},
        "versions": package_versions(),
        "wall_time_s": wall_time,
    }
    if result.tables:
        record["tables"] = sorted(result.tables)
    if error is not None:
        record["error"] = error
    return record


def write_run(
    folder: Path,
    config: Mapping[str, Any],
    record: Mapping[str, Any],
    trace: Mapping[str, np.ndarray],
    tables: Mapping[str, Mapping[str, np.ndarray]] | None = None,
) -> None:
    """Write a complete run folder; record.json goes last and marks the run finished.

    The caller holds the folder (folders.claimed) or writes into a sweep folder it holds.

    Args:
        folder: the run folder; created if needed.
        config: the run's full config, written as config.toml.
        record: the run's record (build_record), written as record.json.
        trace: the run's time-series columns by name, equally long, written as trace.parquet.
        tables: further time series by file name (Result.tables), each written beside it.
    """
    make_folder(folder)
    atomic_write(folder / CONFIG, tomli_w.dumps(dict(config)).encode())
    tables = tables or {}
    for stale in TABLES - set(tables):  # an earlier run's table this run does not write
        (folder / stale).unlink(missing_ok=True)
    for name, columns in {TRACE: trace, **tables}.items():
        sink = pa.BufferOutputStream()
        pq.write_table(pa.table({k: np.asarray(v) for k, v in columns.items()}), sink)
        atomic_write(folder / name, sink.getvalue().to_pybytes())
    atomic_write(folder / RECORD, json.dumps(record, indent=2).encode())


def make_folder(path: Path) -> None:
    """Create an output folder, with a clear error when a file is in the way.

    Args:
        path: the folder to create, with any missing parents.
    """
    if path.exists() and not path.is_dir():
        raise ConfigError("--out", f"{path} is a file; give a folder path")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError("--out", f"cannot create {path} ({exc.strerror})") from None


def is_finished(folder: Path, config_hash_: str | None = None) -> bool:
    """True when the run folder holds a complete run: a readable record.json (of the config
    with hash `config_hash_`, when given) beside its config.toml, a readable trace.parquet and
    every further table the record lists.

    A folder that fails any check (a run killed between files, a truncated or foreign file)
    is not finished, and resuming recomputes it.

    Args:
        folder: a run folder (it need not exist).
        config_hash_: the config_hash its record must carry, or None to accept any.

    Returns:
        Whether the folder holds a complete run (of that config, when given).
    """
    try:
        record = read_record(folder)
        for name in [TRACE, *record.get("tables", [])]:
            pq.read_metadata(folder / name)
        complete = (folder / CONFIG).is_file() and isinstance(record.get("metrics"), dict)
    except (OSError, ValueError, AttributeError, pa.ArrowException):
        return False
    return complete and (config_hash_ is None or record.get("config_hash") == config_hash_)


def read_record(folder: Path) -> dict[str, Any]:
    """The record.json of a finished run.

    Args:
        folder: the run folder.

    Returns:
        The record (see build_record).
    """
    return json.loads((folder / RECORD).read_text())


def read_trace(folder: Path) -> dict[str, np.ndarray]:
    """The trace.parquet of a run folder as columns.

    Args:
        folder: the run folder.

    Returns:
        The trace's columns by name, each shape (samples,).
    """
    table = pq.read_table(folder / TRACE)
    return {name: table[name].to_numpy() for name in table.column_names}


def write_table(path: Path, table: pa.Table) -> None:
    """Write a Parquet table atomically.

    Args:
        path: the .parquet file to write; its folder must exist.
        table: the table to write.
    """
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    atomic_write(path, sink.getvalue().to_pybytes())


def atomic_write(path: Path, data: bytes) -> None:
    """Write to a temporary file beside `path`, flush it to disk, then rename over `path`.

    Args:
        path: the file to write; its folder must exist.
        data: the file's full contents.
    """
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)  # mkstemp creates 0600; results are meant to be shared
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        if exc.filename:
            raise
        raise OSError(exc.errno, exc.strerror, str(path)) from None  # name the file
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    # Make the rename itself durable.
    dir_fd = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(dir_fd)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, str(path)) from None
    finally:
        os.close(dir_fd)


def _json_number(value: float | str | bool | None) -> float | str | bool | None:
    """A metric as JSON allows it: non-finite values become null, as does None (a metric
    that does not apply, such as the self clearance of an arm without checked pairs); a
    name or a flag stays as it is."""
    if value is None or isinstance(value, (str, bool)):
        return value
    value = float(value)
    return value if math.isfinite(value) else None
