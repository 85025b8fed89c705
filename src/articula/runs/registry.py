"""Experiments by name, found through the `articula.experiments` entry-point group.

The run layer knows no experiment: each one is an `Experiment` object in the module that owns
it, named in pyproject.toml (`"motor.current" = "articula.experiments.motor:CURRENT_CONTROL"`).
Loading an entry point imports only that module, so there is no import cycle, and a package of
one's own can add experiments without touching articula.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cache
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel

from articula.errors import ConfigError
from articula.validation import parse_model

GROUP = "articula.experiments"
Progress = Callable[[int, int], None]  # (done, total) of a run's steps


@dataclass(frozen=True)
class Result:
    """What an experiment returns: scalar metrics and equally long time-series columns, and
    optionally more tables and record entries.

    Attributes:
        metrics: the run's scalar metrics by name (units as the experiment defines them).
        trace: the run's time-series columns by name, each shape (samples,).
        tables: further time series by file name ("servo.parquet"), each its columns by name,
            written beside trace.parquet.
        details: further entries of record.json beside metrics (JSON-ready, e.g. per-joint
            limits), by key.
    """

    metrics: dict[str, float]
    trace: dict[str, np.ndarray]
    tables: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    details: dict[str, Any] = field(default_factory=dict)


def _no_paths(data: dict[str, Any], base_dir: Path) -> dict[str, Any]:
    """The default path hook: a config without file paths is returned as it is.

    Args:
        data: a raw config mapping.
        base_dir: the folder of its file (unused).

    Returns:
        `data` itself.
    """
    return data


@dataclass(frozen=True)
class Experiment:
    """A named experiment: its config model and its run function.

    Attributes:
        name: the value of a config's `experiment` key.
        config: the pydantic model of its config (everything but `experiment`).
        run: (config model, progress=None) -> Result; a long experiment reports
            progress(done, total) as it goes, a short one may ignore it.
        resolve_paths: (raw config, folder of its file) -> the config with every file path it
            holds made absolute, so that a run folder's config.toml still finds its files.
    """

    name: str
    config: type[BaseModel]
    run: Callable[..., Result]
    resolve_paths: Callable[[dict[str, Any], Path], dict[str, Any]] = _no_paths


@cache
def _entry_points() -> dict[str, metadata.EntryPoint]:
    """Installed experiments by name."""
    return {ep.name: ep for ep in metadata.entry_points(group=GROUP)}


def names() -> list[str]:
    """Names of every installed experiment, sorted.

    Returns:
        The entry-point names of the `articula.experiments` group, sorted.
    """
    return sorted(_entry_points())


def experiment(name: str, where: str = "") -> Experiment:
    """The installed experiment called `name`; the error for an unknown one names `where`.

    Args:
        name: the experiment's name (a config's `experiment` value).
        where: the config's file, named in the error ("" for none).

    Returns:
        The Experiment its entry point names.
    """
    entry = _entry_points().get(name)
    if entry is None:
        known = ", ".join(names()) or "none installed (pip install -e . registers them)"
        field = f"{where}: experiment" if where else "experiment"
        raise ConfigError(field, f"unknown experiment {name!r}; choose one of: {known}")
    found = entry.load()
    if not isinstance(found, Experiment) or found.name != name:
        raise ConfigError("experiment", f"entry point {entry.value} is not the Experiment {name!r}")
    return found


def parse_config(data: Mapping[str, Any], where: str = "") -> tuple[Experiment, BaseModel]:
    """Validate a config mapping (with its `experiment` key) into its experiment's model;
    errors are prefixed with `where` (a file name) when given.

    Args:
        data: a config mapping with its `experiment` key.
        where: the config's file, prefixed to error fields ("" for none).

    Returns:
        The experiment and its validated config model (without `experiment`).
    """
    body = dict(data)
    if "experiment" not in body:
        field = f"{where}: experiment" if where else "experiment"
        raise ConfigError(field, f"required key is missing; one of: {', '.join(names())}")
    exp = experiment(str(body.pop("experiment")), where)
    return exp, parse_model(exp.config, body, where)


def config_to_dict(exp: Experiment, config: BaseModel) -> dict[str, Any]:
    """The full config (defaults filled in) as a plain mapping with its `experiment` key.

    Args:
        exp: the experiment.
        config: its validated config model.

    Returns:
        The JSON-ready config, `experiment` first; fields that are None are left out.
    """
    return {"experiment": exp.name, **config.model_dump(mode="json", exclude_none=True)}


def with_absolute_paths(data: Mapping[str, Any], base_dir: Path) -> dict[str, Any]:
    """A config read from a file in `base_dir`, its file paths made absolute by its experiment.

    A config without a valid `experiment` key is returned unchanged: validation reports it.

    Args:
        data: a config mapping as read from its file.
        base_dir: the folder of that file, where its relative paths start.

    Returns:
        A copy of the config with its file paths absolute.
    """
    body = dict(data)
    name = body.get("experiment")
    if not isinstance(name, str) or name not in _entry_points():
        return body
    return experiment(name).resolve_paths(body, base_dir)
