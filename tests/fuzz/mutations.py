"""One-field mutations of a valid config, as hypothesis strategies.

A base config is a nested dict (a validated model dumped to JSON types). A `Mutation` changes
one thing of it: sets one node (a leaf, or a whole table or list) to a hostile value, deletes
one key or list item, or adds an unknown key to one table. Values are wrapped in `Value`,
whose repr is a short label, so that a list of 10^5 numbers reads `[0.5] * 10**5` in a report.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from hypothesis import strategies as st

Path = tuple[str | int, ...]
HUGE = 10**5  # items of a huge list, characters of a huge string


@dataclass(frozen=True)
class Value:
    """A value to write into a config, shown by its label."""

    label: str
    data: Any

    def __repr__(self) -> str:
        return self.label

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:  # hypothesis's reports
        printer.text(repr(self))


def _v(data: Any, label: str | None = None) -> Value:
    """A Value labelled by `label`, else by the repr of `data`."""
    return Value(label or repr(data), data)


WRONG_TYPES = (
    _v("text"),
    _v(True),
    _v(False),
    _v([1, 2]),
    _v([]),
    _v({"a": 1}, "{a = 1}"),
    _v({}, "{}"),
)
EXTREMES = (
    _v(0),
    _v(-1),
    _v(0.0),
    _v(-0.0),
    _v(1e308),
    _v(-1e308),
    _v(1e-308),
    _v(5e-324),
    _v(10**30, "10**30"),
    _v(-(10**30), "-10**30"),
    _v(2**63, "2**63"),
    _v(2**63 - 1, "2**63 - 1"),
    _v(-(2**63), "-2**63"),
)
NON_FINITE = (_v(math.nan, "nan"), _v(math.inf, "inf"), _v(-math.inf, "-inf"))
HUGE_SIZES = (
    _v([0.5] * HUGE, "[0.5] * 10**5"),
    _v("x" * HUGE, "'x' * 10**5"),
    _v([[0.1, 0.2, 0.3]] * (HUGE // 10), "[[0.1, 0.2, 0.3]] * 10**4"),
)
ODD_STRINGS = (
    _v(""),
    _v(" "),
    _v("\n"),
    _v("nope"),
    _v("../../etc/passwd"),
    _v("/dev/zero"),
    _v("/tmp"),
    _v("ünïcødé ☃ 𝄞"),
    _v("a\x00b"),
    _v("garbage.stl"),  # a file of random bytes beside the config (bases.write_support_files)
    _v("empty.stl"),  # an empty file beside the config
)
VALUES = EXTREMES + NON_FINITE + WRONG_TYPES + ODD_STRINGS + HUGE_SIZES
# Whole-file replacements of an input file (see conftest.write_input).
FILES = (
    _v("empty", "an empty file"),
    _v("garbage", "random bytes"),
    _v("truncated", "the TOML cut in the middle"),
    _v("bom", "a UTF-8 byte-order mark before the TOML"),
    _v("latin-1", "Latin-1 text, not UTF-8"),
    _v("twice", "the TOML twice (every key defined twice)"),
    _v("json", "JSON instead of TOML"),
    _v("folder", "a folder instead of a file"),
    _v("missing", "no file at all"),
)
# Keys a table does not know: a plain typo, a near miss, an empty key, odd characters.
UNKNOWN_KEYS = ("bogus", "Seed", "", "a.b", "x\ny", "ü")


@dataclass(frozen=True)
class Mutation:
    """One change to a config: "set" the node at `path` to `value`, "delete" it, "add" an
    unknown `key` = `value` to the table at `path`, or replace the whole "file" (`value.data`
    names the replacement, see FILES; conftest.write_input writes it)."""

    kind: str  # "set", "delete", "add", "file" (the whole file) or "none" (the base as it is)
    path: Path
    value: Value | None = None
    key: str = ""

    def apply(self, config: dict[str, Any]) -> dict[str, Any]:
        """A mutated deep copy of `config`."""
        out = copy.deepcopy(config)
        if self.kind in ("none", "file"):
            return out
        if self.kind == "add":
            node = _node(out, self.path)
            node[self.key] = copy.deepcopy(self.value.data if self.value else 1)
            return out
        parent = _node(out, self.path[:-1])
        last = self.path[-1]
        if self.kind == "delete":
            del parent[last]
        else:
            parent[last] = copy.deepcopy(self.value.data if self.value else None)
        return out

    def __repr__(self) -> str:
        where = _dotted(self.path)
        if self.kind == "none":
            return "none (the base as it is)"
        if self.kind == "file":
            return f"the whole file: {self.value!r}"
        if self.kind == "delete":
            return f"delete {where}"
        if self.kind == "add":
            return f"add key {self.key!r} = {self.value!r} to {where or 'the top level'}"
        return f"{where} = {self.value!r}"

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:  # hypothesis's reports
        printer.text(repr(self))


def set_(path: Path, data: Any, label: str | None = None) -> Mutation:
    """Mutation: set the node at `path` to `data` (for @example)."""
    return Mutation("set", tuple(path), _v(data, label))


def delete(path: Path) -> Mutation:
    return Mutation("delete", tuple(path))


def add(path: Path, key: str, data: Any = 1) -> Mutation:
    return Mutation("add", tuple(path), _v(data), key)


UNCHANGED = Mutation("none", ())  # the base as it is (for an @example of a base)


def _dotted(path: Path) -> str:
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text


def _node(config: Any, path: Path) -> Any:
    for part in path:
        config = config[part]
    return config


def node_paths(config: Any, prefix: Path = ()) -> list[Path]:
    """Paths of every node below the root, parents before children."""
    paths: list[Path] = []
    items: Sequence[tuple[str | int, Any]]
    if isinstance(config, dict):
        items = list(config.items())
    elif isinstance(config, list):
        items = list(enumerate(config))
    else:
        return paths
    for key, value in items:
        paths.append((*prefix, key))
        paths.extend(node_paths(value, (*prefix, key)))
    return paths


def table_paths(config: Any, prefix: Path = ()) -> list[Path]:
    """Paths of every table (dict), the root included."""
    paths = [prefix] if isinstance(config, dict) else []
    if isinstance(config, dict):
        for key, value in config.items():
            paths.extend(table_paths(value, (*prefix, key)))
    elif isinstance(config, list):
        for i, value in enumerate(config):
            paths.extend(table_paths(value, (*prefix, i)))
    return paths


def values() -> st.SearchStrategy[Value]:
    """Hostile values: extremes, NaN/inf, wrong types, odd strings, huge sizes."""
    return st.sampled_from(VALUES)


def mutations(config: dict[str, Any]) -> st.SearchStrategy[Mutation]:
    """One-field mutations of `config`, or of its whole file."""
    nodes = node_paths(config)
    tables = table_paths(config)
    sets = st.builds(lambda p, v: Mutation("set", p, v), st.sampled_from(nodes), values())
    deletes = st.builds(delete, st.sampled_from(nodes))
    adds = st.builds(
        lambda p, k, v: Mutation("add", p, v, k),
        st.sampled_from(tables),
        st.sampled_from(UNKNOWN_KEYS),
        st.sampled_from((_v(1), _v("x"), _v(math.nan, "nan"))),
    )
    files = st.builds(lambda v: Mutation("file", (), v), st.sampled_from(FILES))
    # Half the examples set a node; deleting, adding a key and replacing the file share the rest.
    return st.one_of(sets, st.one_of(deletes, adds, files))
