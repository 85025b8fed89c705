"""The input files and --out folders of an example: mutated configs written as TOML, whole
files replaced, and --out variants prepared."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import tomli_w

from tests.fuzz import bases
from tests.fuzz.mutations import Mutation


def write_toml(path: Path, data: Mapping[str, Any]) -> str:
    """Write `data` as TOML (NaN and inf included); returns the text."""
    text = tomli_w.dumps(dict(data))
    path.write_text(text, encoding="utf-8")
    return text


def write_input(path: Path, base: Mapping[str, Any], mutation: Mutation) -> str:
    """Write the mutated `base` at `path` (a "file" mutation replaces the whole file, see
    mutations.FILES); returns what was written, for the report."""
    if mutation.kind != "file":
        return write_toml(path, mutation.apply(dict(base)))
    kind = mutation.value.data if mutation.value else "missing"
    text = tomli_w.dumps(dict(base))
    data = {
        "empty": b"",
        "garbage": bases.GARBAGE,
        "truncated": text[: len(text) // 2].encode(),
        "bom": b"\xef\xbb\xbf" + text.encode(),
        "latin-1": ("# réglage\n" + text).encode("latin-1", errors="replace"),
        "twice": (text + text).encode(),
        "json": json.dumps(dict(base)).encode(),
    }.get(kind)
    if kind == "folder":
        path.mkdir()
    elif data is not None:
        path.write_bytes(data)
    return f"<{mutation.value!r}>"


# --out values: fresh, nested, too long a name, under a file, an existing folder of the user's
# (unrelated files in it), an existing empty folder, the working folder itself, odd names.
OUT_VARIANTS = ("out", "a/b/out", "x" * 300, "rock.stl/out", "mine", "empty", ".", "",
                "out\nx", "-out")  # fmt: skip
USER_FILES = {"notes.txt": "mine\n", "config.toml": "# mine\n", "record.json": "{}",
              ".draft.tmp": "mine"}  # fmt: skip


def prepare_out(folder: Path, name: str) -> Path | None:
    """Create what an --out variant needs (the user's folder and its files); returns the
    folder that must not exist after a refusal, or None when it existed before."""
    if name == "mine":
        (folder / name).mkdir()
        for file, text in USER_FILES.items():
            (folder / name / file).write_text(text)
    elif name == "empty":
        (folder / name).mkdir()
    if name in ("mine", "empty", ".", ""):
        return None
    return folder / name
