"""Experiments by name: a pydantic config class and the function that runs it."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic import BaseModel

from articula.errors import ConfigError
from articula.validation import parse_model


@dataclass(frozen=True)
class Result:
    """What an experiment returns: scalar metrics and equally long time-series columns."""

    metrics: dict[str, float]
    trace: dict[str, np.ndarray]


@dataclass(frozen=True)
class Experiment:
    """A named experiment: its config model and its run function."""

    name: str
    config: type[BaseModel]
    run: Callable[[Any], Result]


_EXPERIMENTS: dict[str, Experiment] = {}


def register(name: str, config: type[BaseModel]) -> Callable[[Callable], Callable]:
    """Decorator that registers `run(config) -> Result` under `name`."""

    def wrap(run: Callable[[Any], Result]) -> Callable[[Any], Result]:
        _EXPERIMENTS[name] = Experiment(name, config, run)
        return run

    return wrap


def experiment(name: str) -> Experiment:
    """The registered experiment called `name`."""
    _load_builtin()
    if name not in _EXPERIMENTS:
        known = ", ".join(sorted(_EXPERIMENTS))
        raise ConfigError("experiment", f"unknown experiment {name!r}; choose one of: {known}")
    return _EXPERIMENTS[name]


def parse_config(data: Mapping[str, Any]) -> tuple[Experiment, BaseModel]:
    """Validate a config mapping (with its `experiment` key) into its experiment's model."""
    body = dict(data)
    if "experiment" not in body:
        raise ConfigError(
            "experiment", 'required key is missing (e.g. experiment = "motor.current")'
        )
    exp = experiment(str(body.pop("experiment")))
    return exp, parse_model(exp.config, body)


def config_to_dict(exp: Experiment, config: BaseModel) -> dict[str, Any]:
    """The full config (defaults filled in) as a plain mapping with its `experiment` key."""
    return {"experiment": exp.name, **config.model_dump(mode="json", exclude_none=True)}


def _load_builtin() -> None:
    """Import the chapter modules so that their experiments register themselves."""
    from articula.experiments import ch2, ch3, ch4  # noqa: F401
