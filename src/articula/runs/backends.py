"""Where a sweep's runs execute: in this process, a local process pool, or Dask."""

from __future__ import annotations

import ctypes
import os
import signal
import socket
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any, TypeVar

from articula.errors import ConfigError

T = TypeVar("T")
PR_SET_PDEATHSIG = 1  # linux/prctl.h
CONNECT_TIMEOUT = 3.0  # [s] to reach a Dask scheduler before any work starts


def check_backend(dask: str | None) -> None:
    """ConfigError for a --dask value that is neither 'local' nor a reachable tcp://HOST:PORT
    (tried now, within CONNECT_TIMEOUT, so that a wrong address fails before any work).

    Args:
        dask: the --dask value: None (no Dask), "local" or "tcp://HOST:PORT" of a scheduler.
    """
    if dask is None or dask == "local":
        return
    host, _, port = dask.removeprefix("tcp://").rpartition(":")
    if not dask.startswith("tcp://") or not host or not port.isdigit():
        raise ConfigError("--dask", f"expected 'local' or tcp://HOST:PORT (got {dask!r})")
    try:
        socket.create_connection((host.strip("[]"), int(port)), CONNECT_TIMEOUT).close()
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
        raise ConfigError("--dask", f"cannot reach the scheduler at {dask} ({reason})") from None


def execute_all(
    task: Callable[[Mapping[str, Any]], T],
    configs: Sequence[Mapping[str, Any]],
    workers: int,
    dask: str | None,
) -> Iterator[T]:
    """task(config) for every config, yielded in completion order from the chosen backend;
    never more worker processes than configs.

    Args:
        task: the function run on each config (picklable, for a pool or Dask).
        configs: the configs, one task call each.
        workers: most worker processes (1 or fewer without Dask: run in this process); also
            the number of workers of a local Dask cluster.
        dask: None for this process or a local process pool, "local" for a loopback Dask
            cluster, "tcp://HOST:PORT" to join a Dask scheduler.

    Yields:
        task(config) of each config, in completion order (not the order of `configs`).
    """
    if not configs:
        return
    workers = min(workers, len(configs))
    if dask is not None:
        yield from _execute_dask(task, configs, dask, workers)
    elif workers <= 1:
        for cfg in configs:
            yield task(cfg)
    else:
        parent = os.getpid()
        with ProcessPoolExecutor(workers, initializer=die_with_parent, initargs=(parent,)) as pool:
            futures = [pool.submit(task, cfg) for cfg in configs]
            for fut in as_completed(futures):
                yield fut.result()


def die_with_parent(parent: int) -> None:
    """Pool initializer: on Linux the kernel kills this worker when its parent dies (even by
    SIGKILL), so a killed sweep leaves no worker behind; elsewhere nothing changes.

    Args:
        parent: process id of the process that started the pool.
    """
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # the parent died before prctl took effect
            os._exit(1)


def _execute_dask(
    task: Callable[[Mapping[str, Any]], T],
    configs: Sequence[Mapping[str, Any]],
    address: str,
    workers: int,
) -> Iterator[T]:
    """Run on Dask: `local` starts a loopback LocalCluster, otherwise join the given scheduler."""
    try:
        from distributed import Client, LocalCluster
        from distributed import as_completed as dask_completed
    except ImportError:
        raise ConfigError("--dask", "needs the dask extra: pip install 'articula[dask]'") from None
    cluster = None
    if address == "local":
        cluster = LocalCluster(
            n_workers=max(workers, 1),
            threads_per_worker=1,
            host="127.0.0.1",
            dashboard_address=None,
            processes=True,
        )
        client = Client(cluster)
    else:
        try:
            client = Client(address, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise ConfigError("--dask", f"cannot reach the scheduler at {address}: {exc}") from None
    try:
        futures = client.map(task, list(configs), pure=False)
        for fut in dask_completed(futures):
            yield fut.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
