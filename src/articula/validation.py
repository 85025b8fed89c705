"""Turn pydantic validation failures into ConfigError lines that name the field."""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ConfigDict, ValidationError

from articula.errors import ConfigError

M = TypeVar("M", bound=BaseModel)


class StrictModel(BaseModel):
    """A frozen parameter bundle: exact types, no unknown keys, ConfigError on bad input."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True)

    def __init__(self, **data: Any) -> None:
        try:
            super().__init__(**data)
        except ValidationError as exc:
            raise config_error_from(exc, type(self).__name__) from None


def field_error(name: str, problem: str) -> ConfigError:
    """A ConfigError for a check across fields, raised inside a validator, that names `name`
    (validation prefixes the path of the table it sits in)."""
    error = ConfigError(name, problem)
    error.loc = (name,)
    return error


def parse_model(model: type[M], data: Mapping[str, Any], where: str = "") -> M:
    """Validate `data` into `model`, raising ConfigError naming the first bad field."""
    try:
        return model.model_validate(dict(data))
    except ValidationError as exc:
        raise config_error_from(exc, where) from None


def config_error_from(exc: ValidationError, where: str = "") -> ConfigError:
    """The first problem of a pydantic ValidationError as a ConfigError."""
    first = exc.errors()[0]
    loc = tuple(str(p) for p in first["loc"])
    inner = first.get("ctx", {}).get("error")
    if isinstance(inner, ConfigError) and inner.loc is not None:
        # A nested StrictModel already turned its own failure into a ConfigError.
        loc, problem = loc + inner.loc, inner.problem
    elif first["type"] == "extra_forbidden":
        problem = "unknown key; remove it or check its spelling"
    elif first["type"] == "missing":
        problem = "required key is missing"
    else:
        problem = str(first["msg"]).removeprefix("Value error, ")
        if loc:  # a check across fields has no loc, and its input is the whole table
            problem += f" (got {first.get('input')!r})"
    path = ".".join(loc) or "config"
    error = ConfigError(f"{where}: {path}" if where else path, problem)
    error.loc = loc
    return error


def load_toml(path: Path) -> dict[str, Any]:
    """Read a TOML file into a dict, with errors that name the file."""
    if not path.is_file():
        raise ConfigError(str(path), "file not found; pass the path of an existing TOML file")
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(str(path), f"not valid TOML: {exc}") from None
    except UnicodeDecodeError:
        raise ConfigError(str(path), "not a UTF-8 text file; TOML must be UTF-8") from None
    except OSError as exc:
        raise ConfigError(str(path), f"cannot read the file ({exc.strerror})") from None
