"""Sweep files: a [base] config, a [grid] of dotted keys to lists, [[runs]] of partial configs."""

from __future__ import annotations

import copy
import itertools
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from articula.errors import ConfigError
from articula.limits import MAX_RUNS
from articula.runs import records
from articula.runs.registry import config_to_dict, parse_config, with_absolute_paths


def expand_sweep(
    spec: Mapping[str, Any],
    base_dir: Path | None = None,
    max_runs: int = MAX_RUNS,
    where: str = "",
) -> list[dict[str, Any]]:
    """Configs of a sweep: `base` updated by every point of `grid` and every entry of `runs`.

    `grid` maps dotted keys ("controller.filter_order") to lists of values and is expanded as a
    Cartesian product; `runs` is a list of partial configs. Every config is validated here, so
    a bad sweep fails before anything runs. File paths in the configs start at `base_dir`
    (the sweep file's folder) and come out absolute. A sweep of more than `max_runs` configs
    is refused before any is built. Errors name `where` (the sweep file) and the point.

    Args:
        spec: the sweep file's tables: `base`, `grid` and `runs` (each optional).
        base_dir: the folder relative file paths start at (the sweep file's), or None to
            leave paths as they are.
        max_runs: the most configs the sweep may have.
        where: the sweep file, named in errors ("" for none).

    Returns:
        The full, validated configs: every `runs` entry for each grid point in turn.
    """
    unknown = set(spec) - {"base", "grid", "runs"}
    if unknown:
        raise ConfigError(sorted(unknown)[0], "unknown sweep key; use base, grid and runs")
    base = copy.deepcopy(spec.get("base", {}))
    grid = copy.deepcopy(spec.get("grid", {}))
    runs = copy.deepcopy(spec.get("runs", [{}]))
    if not isinstance(base, dict):
        raise ConfigError("base", "must be a table of config keys ([base])")
    if not isinstance(grid, dict):
        raise ConfigError("grid", 'must be a table of dotted keys to lists ([grid] "a.b" = [...])')
    if not isinstance(runs, list) or not all(isinstance(r, dict) for r in runs):
        raise ConfigError("runs", "must be a list of tables ([[runs]])")
    if not runs:
        raise ConfigError("runs", "is empty; give at least one [[runs]] table, or leave it out")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise ConfigError(f"grid.{key}", "must be a non-empty list of values")
    size = math.prod(len(values) for values in grid.values()) * len(runs)
    if size > max_runs:
        raise ConfigError(
            "grid",
            f"the sweep has {size:,} runs, more than the limit of {max_runs:,}; split it, or "
            f"raise the limit (articula sweep --max-runs {size})",
        )
    configs = []
    for point in itertools.product(*grid.values()):
        for index, run in enumerate(runs):
            cfg = _deep_merge(base, run)
            for key, value in zip(grid, point, strict=True):
                _set_dotted(cfg, key, value)
            if base_dir is not None:
                cfg = with_absolute_paths(cfg, base_dir)
            values = ", ".join(f"{k} = {v!r}" for k, v in zip(grid, point, strict=True))
            label = ", ".join(p for p in (where, values, f"runs[{index}]" * (len(runs) > 1)) if p)
            configs.append(config_to_dict(*parse_config(cfg, label)))
    hashes = [records.config_hash(c) for c in configs]
    if len(set(hashes)) != len(hashes):
        raise ConfigError("grid", "two points of the sweep give the same config; remove the repeat")
    return configs


def _deep_merge(a: Mapping[str, Any], b: Mapping[str, Any]) -> dict[str, Any]:
    """A deep copy of `a` with `b` laid over it (tables merged, everything else replaced)."""
    merged = copy.deepcopy(dict(a))
    for k, v in b.items():
        if isinstance(v, Mapping) and isinstance(merged.get(k), Mapping):
            merged[k] = _deep_merge(merged[k], v)
        else:
            merged[k] = copy.deepcopy(v)
    return merged


def _set_dotted(cfg: dict[str, Any], key: str, value: Any) -> None:
    """Set cfg["a"]["b"] for key "a.b", creating tables as needed; a number indexes a list
    of the base config ("obstacles.0.position" is the first obstacle's position)."""
    parts = key.split(".")
    node: Any = cfg
    for depth, part in enumerate(parts):
        if isinstance(node, list):
            if not (part.isdigit() and int(part) < len(node)):
                raise ConfigError(
                    f"grid.{key}", f"{part!r} is not an index of the base's list of {len(node)}"
                )
            slot: Any = int(part)
        elif isinstance(node, dict):
            slot = part
        else:
            raise ConfigError(
                f"grid.{key}", f"{parts[depth - 1]!r} is neither a table nor a list in the base"
            )
        if depth == len(parts) - 1:
            node[slot] = value
        elif isinstance(node, dict):
            node = node.setdefault(slot, {})
        else:
            node = node[slot]
