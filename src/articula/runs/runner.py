"""Run one config or a sweep of configs, locally or on Dask, never recomputing a finished run."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from articula.errors import ConfigError
from articula.runs import records
from articula.runs.registry import config_to_dict, parse_config

RESULTS = "results.parquet"


@dataclass(frozen=True)
class RunOutput:
    """A finished run as it travels back from a worker: config, record and trace."""

    config: dict[str, Any]
    record: dict[str, Any]
    trace: dict[str, np.ndarray]


def execute(config: Mapping[str, Any], where: str = "") -> RunOutput:
    """Validate and run one config (a mapping with its `experiment` key); validation errors
    name `where` (its file) when given."""
    exp, model = parse_config(config, where)
    full = config_to_dict(exp, model)
    start = time.perf_counter()
    result = exp.run(model)
    wall = time.perf_counter() - start
    return RunOutput(full, records.build_record(full, result, wall), result.trace)


def normalized(config: Mapping[str, Any]) -> dict[str, Any]:
    """A config validated and completed with its defaults, as its run folder records it."""
    return config_to_dict(*parse_config(config))


def run_to_folder(config: Mapping[str, Any], out: Path, where: str = "") -> dict[str, Any]:
    """Run one config and write its run folder; returns the record. Bad input fails before
    anything is written."""
    output = execute(config, where)
    records.write_run(out, output.config, output.record, output.trace)
    return output.record


def run_sweep(
    configs: Sequence[Mapping[str, Any]],
    out: Path,
    workers: int = 1,
    dask: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> pa.Table:
    """Run every config not yet finished under `out`, then write and return results.parquet.

    Each config is validated and completed with its defaults first, so a run folder is named
    by the same hash whether its config came complete (from expand_sweep) or partial.
    """
    check_backend(dask)
    configs = [normalized(c) for c in configs]
    records.make_folder(out)
    folders = {records.config_hash(c): out / records.config_hash(c) for c in configs}
    todo = [c for c in configs if not records.is_finished(folders[records.config_hash(c)])]
    done = len(configs) - len(todo)
    if progress:
        progress(done, len(configs))
    for output in _execute_all(todo, workers, dask):
        records.write_run(folders[output.record["config_hash"]], output.config, output.record,
                          output.trace)  # fmt: skip
        done += 1
        if progress:
            progress(done, len(configs))
    table = results_table(configs, out)
    records.write_table(out / RESULTS, table)
    return table


def check_backend(dask: str | None) -> None:
    """Reject a --dask value that is neither 'local' nor a tcp:// address."""
    if dask is not None and dask != "local" and not dask.startswith("tcp://"):
        raise ConfigError("--dask", f"expected 'local' or tcp://HOST:PORT (got {dask!r})")


def results_table(configs: Sequence[Mapping[str, Any]], out: Path) -> pa.Table:
    """One row per run: its hash, flattened config values and metrics."""
    rows = []
    for cfg in configs:
        h = records.config_hash(cfg)
        record = records.read_record(out / h)
        row = {"run": h, **_flatten(cfg), **record["metrics"], "wall_time_s": record["wall_time_s"]}
        rows.append(row)
    return pa.Table.from_pylist(rows)


def _execute_all(
    configs: Sequence[Mapping[str, Any]], workers: int, dask: str | None
) -> Iterator[RunOutput]:
    """Yield finished runs in completion order from the chosen backend."""
    if not configs:
        return
    if dask is not None:
        yield from _execute_dask(configs, dask, workers)
    elif workers <= 1:
        for cfg in configs:
            yield execute(cfg)
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(execute, cfg) for cfg in configs]
            for fut in as_completed(futures):
                yield fut.result()


def _execute_dask(
    configs: Sequence[Mapping[str, Any]], address: str, workers: int
) -> Iterator[RunOutput]:
    """Run on Dask: `local` starts a loopback LocalCluster, otherwise join the given scheduler."""
    try:
        from distributed import Client, LocalCluster
        from distributed import as_completed as dask_completed
    except ImportError:
        raise ConfigError("--dask", "needs the dask extra: pip install 'articula[dask]'") from None
    cluster = None
    if address == "local":
        cluster = LocalCluster(
            n_workers=max(workers, 1), threads_per_worker=1, host="127.0.0.1",
            dashboard_address=None, processes=True,
        )  # fmt: skip
        client = Client(cluster)
    else:
        try:
            client = Client(address, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise ConfigError("--dask", f"cannot reach the scheduler at {address}: {exc}") from None
    try:
        futures = client.map(execute, list(configs), pure=False)
        for fut in dask_completed(futures):
            yield fut.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _flatten(cfg: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Dotted keys for nested tables; values that are not scalars are left out."""
    flat: dict[str, Any] = {}
    for k, v in cfg.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping):
            flat.update(_flatten(v, key + "."))
        elif isinstance(v, (int, float, str, bool)):
            flat[key] = v
    return flat
