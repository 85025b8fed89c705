"""Help that names option types in words: ``--json``, ``--out PATH``, ``--workers INTEGER``.

Typer prints every parameter's type as ``<bool>``, ``<int range>``, ``<path>``; a flag takes no
value, so it shows none, and a value shows as the word click's own help uses for it.
"""

from __future__ import annotations

import typer
from typer.core import TyperArgument, TyperGroup, TyperOption

WORDS = {
    "int": "INTEGER",
    "int range": "INTEGER",
    "float": "NUMBER",
    "float range": "NUMBER",
    "str": "TEXT",
    "path": "PATH",
    "file": "FILE",
    "directory": "FOLDER",
}


class WordArgument(TyperArgument):
    """A positional argument whose type shows as a word."""

    def display_type_rich(self, ctx: typer.Context) -> str | None:
        """The argument's type as a word (a choice lists its values)."""
        return type_word(self.display_type(ctx))


def type_word(label: str) -> str:
    """The word for typer's type label: ``<int range>`` is INTEGER, ``<a|b>`` stays a|b."""
    bare = label.strip("<>")
    if "|" in bare:
        return bare
    return WORDS.get(bare, bare.upper())


def speak_in_words(command: typer.core.TyperCommand | TyperGroup, ctx: typer.Context) -> None:
    """Give every parameter of the command tree a metavar in words (flags none)."""
    for param in command.get_params(ctx):  # with --help, which click adds
        if isinstance(param, TyperOption):
            if param.metavar is None:
                param.metavar = "" if param.is_flag else type_word(param.display_type(ctx))
        elif isinstance(param, TyperArgument):
            param.__class__ = WordArgument  # the type column of an argument ignores its metavar
    for sub in getattr(command, "commands", {}).values():
        speak_in_words(sub, ctx)
