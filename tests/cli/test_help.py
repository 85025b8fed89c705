"""The command line speaks to users: --version, a top-level help that says what articula is
and shows its most common commands, an example in every command's help, types in words."""

from __future__ import annotations

import importlib.metadata
import re
from pathlib import Path

import pytest
import typer

from articula.cli import app, main


def run(capsys, *argv: str) -> str:
    """What `articula ARGV` prints on stdout (it must end with status 0)."""
    try:
        main(list(argv))
    except SystemExit as exit_:
        assert exit_.code == 0
    return capsys.readouterr().out


def leaf_commands() -> list[tuple[str, ...]]:
    """The path of every command that does work (not a group)."""
    found = []

    def walk(command, path):
        subs = getattr(command, "commands", None)
        if subs is None:
            found.append(path)
        else:
            for name, sub in subs.items():
                walk(sub, (*path, name))

    walk(typer.main.get_command(app), ())
    return found


def test_version_is_the_installed_distributions(capsys):
    assert run(capsys, "--version").strip() == f"articula {importlib.metadata.version('articula')}"


def test_top_level_help_says_what_articula_is_and_shows_common_commands(capsys):
    text = run(capsys, "--help")
    assert "articulated robots" in text
    for command in ("articula reproduce all", "articula plan", "articula run"):
        assert command in text
    assert "--version" in text


@pytest.mark.parametrize("path", leaf_commands(), ids=" ".join)
def test_every_command_help_has_an_example_and_types_in_words(capsys, path):
    text = run(capsys, *path, "--help")
    assert re.search(r"^\s*Example: articula " + " ".join(path), text, re.M), text
    assert not re.search(r"<(bool|str|int|float|path)[^>]*>", text), text
    assert "--json <" not in text and "--help <" not in text


def test_a_flag_shows_no_type_and_a_value_a_word(capsys):
    text = run(capsys, "plan", "--help")
    assert re.search(r"^\s*--json\s+Print one JSON object", text, re.M), text
    assert re.search(r"^\s*--out FOLDER\s", text, re.M), text


def test_live_record_into_a_foreign_folder_names_record_and_force(main_fails, tmp_path):
    folder = tmp_path / "notes"
    folder.mkdir()
    (folder / "mine.txt").write_text("a user's file")
    scene = Path(__file__).resolve().parents[2] / "src/articula/book/ch1/configs/two_obstacles.toml"
    line = main_fails("live", scene, "--record", folder)
    assert "--record" in line and "--force" in line, line
    assert (folder / "mine.txt").read_text() == "a user's file"
