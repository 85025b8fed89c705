"""Turn pydantic validation failures into ConfigError lines that name the field."""

from __future__ import annotations

import re
import tomllib
from collections.abc import Callable, Iterator, Mapping
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path
from typing import Annotated, Any, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from articula.errors import ConfigError, InfeasibleError
from articula.limits import MAX_ANGLE, MAX_LENGTH

M = TypeVar("M", bound=BaseModel)
# Field types shared by parameter models: finite floats within ±MAX_MAGNITUDE, which holds any
# physical value of this project in SI units and keeps 1e308 from reaching native code.
MAX_MAGNITUDE = 1e12
Finite = Annotated[float, Field(ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, le=MAX_MAGNITUDE, allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, le=MAX_MAGNITUDE, allow_inf_nan=False)]
Seed = Annotated[int, Field(ge=0, lt=2**63)]  # what numpy's generators and numba's ints take
# Geometry within the stated limits (limits.py): coordinates and sizes [m], angles [rad].
Length = Annotated[float, Field(ge=-MAX_LENGTH, le=MAX_LENGTH, allow_inf_nan=False)]
PositiveLength = Annotated[float, Field(gt=0, le=MAX_LENGTH, allow_inf_nan=False)]
Radians = Annotated[float, Field(ge=-MAX_ANGLE, le=MAX_ANGLE, allow_inf_nan=False)]
Point = Annotated[list[Length], Field(min_length=3, max_length=3)]


class StrictModel(BaseModel):
    """A frozen parameter bundle: exact types, no unknown keys, ConfigError on bad input."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True)

    def __init__(self, **data: Any) -> None:
        try:
            super().__init__(**data)
        except ValidationError as exc:
            # Built in code, not from a file: name the field as ClassName.field.
            raise config_error_from(exc, owner=type(self).__name__) from None


def field_error(name: str, problem: str) -> ConfigError:
    """A ConfigError for a check across fields, raised inside a validator, that names `name`
    (validation prefixes the path of the table it sits in).

    Args:
        name: the field the problem is reported on, relative to its table.
        problem: what is wrong and how to fix it.

    Returns:
        The error, with its location set to `name`.
    """
    error = ConfigError(name, problem)
    error.loc = (name,)
    return error


def parse_model(model: type[M], data: Mapping[str, Any], where: str = "") -> M:
    """Validate `data` into `model`, raising ConfigError naming the first bad field.

    Args:
        model: the pydantic model class to build.
        data: the raw table, e.g. as read from a TOML file.
        where: the source of the data (a file name), prefixed to the field in errors.

    Returns:
        The validated model.
    """
    try:
        return model.model_validate(dict(data))
    except ValidationError as exc:
        raise config_error_from(exc, where) from None


def config_error_from(exc: ValidationError, where: str = "", owner: str = "") -> ConfigError:
    """The first problem of a pydantic ValidationError as a ConfigError.

    `where` (a file name) prefixes the field's path as "where: a.b"; `owner` (a class name) as
    "Owner.a.b".

    Args:
        exc: the pydantic failure.
        where: the source of the data (a file name), or "".
        owner: the class the fields belong to, or "".

    Returns:
        The error, naming the path of the first bad field.
    """
    first = exc.errors()[0]
    # Keys and list indices only: pydantic adds the name of a union's member it tried
    # ("constrained-float", "list[...]"), which is no key of the user's file.
    loc = tuple(str(p) for p in first["loc"] if re.fullmatch(r"\w+", str(p)))
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
    path = ".".join((owner, *loc) if owner else loc) or "config"
    error = ConfigError(f"{where}: {path}" if where else path, problem)
    error.loc = loc
    return error


@contextmanager
def fields_renamed(rename: Callable[[str | None], str | None]) -> Iterator[None]:
    """Re-raise a ConfigError or InfeasibleError raised inside with its field renamed by
    `rename` (which returns None to leave an error as it is).

    Args:
        rename: maps an error's field to the name to report, or to None to keep the error.

    Yields:
        Nothing; errors raised in the block are renamed.
    """
    try:
        yield
    except ConfigError as exc:
        field = rename(exc.field)
        if field is None:
            raise
        raise ConfigError(field, exc.problem) from None
    except InfeasibleError as exc:
        field = rename(exc.field)
        if field is None:
            raise
        raise InfeasibleError(exc.problem, field) from None


def fields_as(paths: Mapping[str, str]) -> AbstractContextManager[None]:
    """Rename error fields from the argument name the library used to the config path the
    user wrote (e.g. "q0" -> "robot.q0"); other errors pass unchanged.

    Args:
        paths: config path by argument name.

    Returns:
        A context manager that renames the errors raised in its block.
    """
    return fields_renamed(lambda field: paths.get(field) if field is not None else None)


def load_toml(path: Path) -> dict[str, Any]:
    """Read a TOML file into a dict, with errors that name the file.

    Args:
        path: the TOML file (UTF-8).

    Returns:
        The file's tables and values.
    """
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


def load_experiment_config(path: Path | None, model: type[M]) -> M:
    """An experiment's config file read and validated (its `experiment` key optional), or the
    model's defaults.

    Args:
        path: the TOML file; None: the defaults.
        model: the experiment's config model.

    Returns:
        The config (ConfigError naming the file and key where it does not read).
    """
    data = {} if path is None else load_toml(path)
    data.pop("experiment", None)
    return parse_model(model, data, str(path or "defaults"))
