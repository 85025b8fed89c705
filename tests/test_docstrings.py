"""Every public function and class of the library documents each of its parameters.

Like python-control's docstring test: the public API is every function and class defined in a
public module of the library (a module and a name without a leading underscore), the chapter
homes (``articula.book``) and the command line (``articula.cli``) excepted, as they are the
application, documented in the guides. Docstrings are Google style, parsed by griffe as the
API reference (mkdocstrings) renders them: a callable's parameters are listed under ``Args:``
and what it gives back under ``Returns:`` (or ``Yields:``); the fields of a dataclass, a named
tuple or a pydantic model under ``Attributes:`` (or ``Args:``).
"""

from __future__ import annotations

import dataclasses
import enum
import importlib
import inspect
import logging
import pkgutil
from collections.abc import Callable, Iterator

import griffe
import pydantic
import pytest

import articula

EXCLUDED_PACKAGES = ("articula.book", "articula.cli")
# The book's values and chapter 2's tuning study: the examples and guides call them, so they
# are API too (the experiments themselves are in articula.experiments, public).
BOOK_API = ("articula.book.ch2.book_values", "articula.book.ch2.tuning")
PARAMETER_SECTIONS = {"parameters", "other_parameters"}
FIELD_SECTIONS = {"attributes", "parameters"}
RETURN_SECTIONS = {"returns", "yields"}

logging.getLogger("griffe").setLevel(logging.ERROR)  # no annotations: the text is what counts


def public_modules() -> list[str]:
    """Names of the library's public modules."""
    names = ["articula"]
    for info in pkgutil.walk_packages(articula.__path__, "articula."):
        parts = info.name.split(".")
        if any(p.startswith("_") for p in parts[1:]):
            continue
        if info.name.startswith(EXCLUDED_PACKAGES) and info.name not in BOOK_API:
            continue
        names.append(info.name)
    return sorted(names)


def sections(doc: str | None) -> dict[str, set[str]]:
    """The docstring's sections by kind, each with the names it lists."""
    found: dict[str, set[str]] = {}
    for section in griffe.Docstring(doc or "").parse("google"):
        kind = section.kind.value
        values = section.value if isinstance(section.value, list) else [section.value]
        found.setdefault(kind, set()).update(getattr(v, "name", "") for v in values)
    return found


def parameter_names(func: Callable) -> list[str]:
    """The parameters a caller passes (no self, cls, *args or **kwargs catch-alls)."""
    try:
        signature = inspect.signature(func)
    except (TypeError, ValueError):
        return []
    return [
        p.name
        for p in signature.parameters.values()
        if p.name not in ("self", "cls")
        and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
        and not p.name.startswith("_")
    ]


def returns_something(func: Callable) -> bool:
    """Whether the callable is annotated to give back a value."""
    annotation = inspect.signature(func).return_annotation
    return annotation not in (inspect.Signature.empty, None, "None", "NoReturn", "Never")


def callable_problems(name: str, func: Callable) -> Iterator[str]:
    """What the callable's docstring leaves out."""
    doc = inspect.getdoc(func)
    if not doc:
        yield f"{name}: no docstring"
        return
    found = sections(doc)
    documented = set().union(*(found.get(k, set()) for k in PARAMETER_SECTIONS))
    for param in parameter_names(func):
        if param not in documented:
            yield f"{name}: parameter {param!r} is not under Args:"
    if returns_something(func) and not RETURN_SECTIONS & found.keys():
        yield f"{name}: no Returns: section"


def field_names(cls: type) -> list[str]:
    """The public fields of a dataclass, named tuple or pydantic model (else none)."""
    if issubclass(cls, pydantic.BaseModel):
        return [n for n in cls.model_fields if not n.startswith("_")]
    if dataclasses.is_dataclass(cls):
        return [f.name for f in dataclasses.fields(cls) if f.init and not f.name.startswith("_")]
    if issubclass(cls, tuple) and hasattr(cls, "_fields"):
        return list(cls._fields)
    return []


def own_methods(cls: type) -> Iterator[tuple[str, Callable]]:
    """The public methods the class itself defines (properties have no parameters)."""
    for attr, value in vars(cls).items():
        if attr.startswith("_"):
            continue
        if isinstance(value, staticmethod | classmethod):
            yield attr, value.__func__
        elif inspect.isfunction(value):
            yield attr, value


def class_problems(name: str, cls: type) -> Iterator[str]:
    """What the class's docstrings leave out."""
    doc = inspect.getdoc(cls) if cls.__doc__ else None
    if not doc:
        yield f"{name}: no docstring"
        return
    found = sections(doc)
    fields = field_names(cls)
    if fields:
        documented = set().union(*(found.get(k, set()) for k in FIELD_SECTIONS))
        for field in fields:
            if field not in documented:
                yield f"{name}: field {field!r} is not under Attributes:"
    elif not issubclass(cls, enum.Enum) and "__init__" in vars(cls):
        init_doc = inspect.getdoc(cls.__init__) if cls.__init__.__doc__ else ""
        documented = set().union(*(found.get(k, set()) for k in PARAMETER_SECTIONS))
        documented |= set().union(*(sections(init_doc).get(k, set()) for k in PARAMETER_SECTIONS))
        for param in parameter_names(cls.__init__):
            if param not in documented:
                yield f"{name}: constructor parameter {param!r} is not under Args:"
    if issubclass(cls, pydantic.BaseModel):
        return  # validators and model methods are pydantic's hooks, not API
    for attr, method in own_methods(cls):
        yield from callable_problems(f"{name}.{attr}", method)


def module_problems(module_name: str) -> list[str]:
    """Every gap in one module's public docstrings."""
    module = importlib.import_module(module_name)
    problems = []
    for attr, value in vars(module).items():
        if attr.startswith("_") or getattr(value, "__module__", None) != module_name:
            continue
        value = getattr(value, "py_func", value)  # a numba kernel: the Python function it compiles
        if inspect.isclass(value):
            problems.extend(class_problems(f"{module_name}.{attr}", value))
        elif inspect.isfunction(value):
            problems.extend(callable_problems(f"{module_name}.{attr}", value))
    return problems


@pytest.mark.parametrize("module_name", public_modules())
def test_public_api_documents_every_parameter(module_name):
    problems = module_problems(module_name)
    assert not problems, "\n".join(problems)


def test_the_check_finds_an_undocumented_parameter():
    def documented(x: float) -> float:
        """Twice x.

        Args:
            x: a length [m].

        Returns:
            Twice the length [m].
        """
        return 2 * x

    def undocumented(x: float, y: float) -> float:
        """Sum.

        Args:
            x: a length [m].
        """
        return x + y

    assert list(callable_problems("documented", documented)) == []
    assert list(callable_problems("undocumented", undocumented)) == [
        "undocumented: parameter 'y' is not under Args:",
        "undocumented: no Returns: section",
    ]


def test_the_check_finds_an_undocumented_field_or_constructor_parameter():
    @dataclasses.dataclass
    class Pose:
        """A pose.

        Attributes:
            position: where [m].
        """

        position: float
        yaw: float

    class Motor:
        """A motor.

        Args:
            R: resistance [Ω].
        """

        def __init__(self, R: float, L: float) -> None:
            self.R, self.L = R, L

    assert list(class_problems("Pose", Pose)) == ["Pose: field 'yaw' is not under Attributes:"]
    assert list(class_problems("Motor", Motor)) == [
        "Motor: constructor parameter 'L' is not under Args:"
    ]
