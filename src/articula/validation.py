"""Turn pydantic validation failures into ConfigError lines that name the field."""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from articula.errors import ConfigError

M = TypeVar("M", bound=BaseModel)


def parse_model(model: type[M], data: Mapping[str, Any], where: str = "") -> M:
    """Validate `data` into `model`, raising ConfigError naming the first bad field."""
    try:
        return model.model_validate(dict(data))
    except ValidationError as exc:
        raise config_error_from(exc, where) from None


def config_error_from(exc: ValidationError, where: str = "") -> ConfigError:
    """The first problem of a pydantic ValidationError as a ConfigError."""
    first = exc.errors()[0]
    path = ".".join(str(p) for p in first["loc"]) or "config"
    field = f"{where}: {path}" if where else path
    if first["type"] == "extra_forbidden":
        return ConfigError(field, "unknown key; remove it or check its spelling")
    if first["type"] == "missing":
        return ConfigError(field, "required key is missing")
    message = str(first["msg"]).removeprefix("Value error, ")
    if not first["loc"]:  # a check across fields: the input is the whole table
        return ConfigError(field, message)
    return ConfigError(field, f"{message} (got {first.get('input')!r})")


def load_toml(path: Path) -> dict[str, Any]:
    """Read a TOML file into a dict, with errors that name the file."""
    if not path.is_file():
        raise ConfigError(str(path), "file not found; pass the path of an existing TOML file")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(str(path), f"not valid TOML: {exc}") from None
