"""Run one config or a sweep of configs, locally or on Dask, never recomputing a finished run."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from articula.errors import InfeasibleError
from articula.runs import records
from articula.runs.backends import check_backend, execute_all
from articula.runs.folders import RESULTS, check_out, claimed
from articula.runs.registry import Progress, Result, config_to_dict, parse_config
from articula.validation import fields_renamed

FLAT_LIST_LIMIT = 16  # results.parquet spreads a config list this long or shorter into columns


@dataclass(frozen=True)
class RunOutput:
    """A finished run as it travels back from a worker: config, record, trace and tables.

    Attributes:
        config: the run's full config (defaults filled in), with its `experiment` key.
        record: the run's record (records.build_record).
        trace: the run's time-series columns by name; empty for a run that could not be done.
        tables: further time series by file name (Result.tables).
    """

    config: dict[str, Any]
    record: dict[str, Any]
    trace: dict[str, np.ndarray]
    tables: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)


def execute(
    config: Mapping[str, Any], where: str = "", progress: Progress | None = None
) -> RunOutput:
    """Validate and run one config (a mapping with its `experiment` key); validation errors
    name `where` (its file) when given; `progress` is handed to the experiment.

    Args:
        config: a config mapping with its `experiment` key.
        where: the config's file, prefixed to error fields ("" for none).
        progress: called with (steps done, total steps) of the run, or None.

    Returns:
        The finished run.
    """
    exp, model = parse_config(config, where)
    full = config_to_dict(exp, model)
    start = time.perf_counter()
    with named_by_file(where):
        result = exp.run(model, progress=progress)
    wall = time.perf_counter() - start
    record = records.build_record(full, result, wall)
    return RunOutput(full, record, result.trace, result.tables)


def named_by_file(where: str) -> AbstractContextManager[None]:
    """Prefix the field of a ConfigError or InfeasibleError raised inside with `where` (the
    config's file), as validation errors are; without `where`, leave errors as they are.

    Args:
        where: the config's file ("" leaves errors as they are).

    Returns:
        A context manager renaming the errors raised inside it.
    """
    if not where:
        return nullcontext()
    return fields_renamed(lambda field: f"{where}: {field}" if field else where)


def execute_or_fail(config: Mapping[str, Any]) -> RunOutput:
    """execute(config), or, for a config that cannot be done (InfeasibleError: a start in
    collision, a path out of reach), a run whose record says why, so that one such point
    of a sweep does not stop the others; resuming does not retry it (the same config fails
    the same way).

    Args:
        config: a config mapping with its `experiment` key.

    Returns:
        The finished run, or one with empty metrics and trace whose record carries `error`.
    """
    try:
        return execute(config)
    except InfeasibleError as exc:
        full = normalized(config)
        record = records.build_record(full, Result({}, {}), 0.0, error=str(exc))
        return RunOutput(full, record, {})


def normalized(config: Mapping[str, Any]) -> dict[str, Any]:
    """A config validated and completed with its defaults, as its run folder records it.

    Args:
        config: a config mapping with its `experiment` key.

    Returns:
        The full config as a plain mapping (config_to_dict).
    """
    return config_to_dict(*parse_config(config))


def run_to_folder(
    config: Mapping[str, Any],
    out: Path,
    where: str = "",
    force: bool = False,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """Run one config and write its run folder `out`; returns the record.

    Bad input, and an `out` that is a file or holds files articula did not write (unless
    `force`), fail before the run starts; nothing is written then. The folder is held while
    its files are written, so two processes writing one folder never mix their files.

    Args:
        config: a config mapping with its `experiment` key.
        out: the run folder to write.
        where: the config's file, prefixed to error fields ("" for none).
        force: write into an `out` holding files articula did not write (only articula's own
            files are replaced).
        progress: called with (steps done, total steps) of the run, or None.

    Returns:
        The run's record, as written to record.json.
    """
    parse_config(config, where)
    check_out(out, "run", force)
    output = execute(config, where, progress)
    with claimed(out, "run", force):
        records.write_run(out, output.config, output.record, output.trace, output.tables)
    return output.record


def run_sweep(
    configs: Sequence[Mapping[str, Any]],
    out: Path,
    workers: int = 1,
    dask: str | None = None,
    progress: Callable[[int, int], None] | None = None,
    force: bool = False,
) -> pa.Table:
    """Run every config not yet finished under `out`, then write and return results.parquet.

    Each config is validated and completed with its defaults first, so a run folder is named
    by the same hash whether its config came complete (from expand_sweep) or partial. The
    sweep holds `out` while it runs (a second sweep into it is refused); a run folder counts
    as finished only if all its files are there and readable (records.is_finished).

    Args:
        configs: the sweep's configs, each with its `experiment` key (complete or partial).
        out: the sweep folder; each run goes to a subfolder named by its config hash.
        workers: most worker processes (see backends.execute_all).
        dask: None, "local" or "tcp://HOST:PORT" of a Dask scheduler (see backends.execute_all).
        progress: called with (runs done, total runs), finished runs of before included, or
            None.
        force: write into an `out` holding files articula did not write.

    Returns:
        The results table (results_table), as written to results.parquet.
    """
    check_backend(dask)
    configs = [normalized(c) for c in configs]
    with claimed(out, "sweep", force):
        hashes = [records.config_hash(c) for c in configs]
        todo = [
            c for c, h in zip(configs, hashes, strict=True) if not records.is_finished(out / h, h)
        ]
        done = len(configs) - len(todo)
        if progress:
            progress(done, len(configs))
        for output in execute_all(execute_or_fail, todo, workers, dask):
            folder = out / output.record["config_hash"]
            records.write_run(folder, output.config, output.record, output.trace, output.tables)
            done += 1
            if progress:
                progress(done, len(configs))
        table = results_table(configs, out)
        records.write_table(out / RESULTS, table)
    return table


def results_table(configs: Sequence[Mapping[str, Any]], out: Path) -> pa.Table:
    """One row per run: its hash, flattened config values, metrics, and `error` (null, or why
    the run could not be done).

    Args:
        configs: the full configs of the sweep's runs, every one finished.
        out: the sweep folder holding their run folders.

    Returns:
        One row per config, in order: run (the hash), config values by dotted key, metrics,
        wall_time_s [s] and error.
    """
    rows = []
    for cfg in configs:
        h = records.config_hash(cfg)
        record = records.read_record(out / h)
        row = {"run": h, **_flatten(cfg), **record["metrics"]}
        rows.append({**row, "wall_time_s": record["wall_time_s"], "error": record.get("error")})
    return pa.Table.from_pylist(rows)


def _flatten(cfg: Mapping[str, Any] | list[Any], prefix: str = "") -> dict[str, Any]:
    """Scalars by dotted key, as a sweep's [grid] names them ("obstacles.0.position.1"); lists
    longer than FLAT_LIST_LIMIT (a waypoint list) are left out."""
    items = cfg.items() if isinstance(cfg, Mapping) else enumerate(cfg)
    flat: dict[str, Any] = {}
    for k, v in items:
        key = f"{prefix}{k}"
        if isinstance(v, Mapping) or (isinstance(v, list) and len(v) <= FLAT_LIST_LIMIT):
            flat.update(_flatten(v, key + "."))
        elif isinstance(v, (int, float, str, bool)):
            flat[key] = v
    return flat
