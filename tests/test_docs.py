"""The documentation site covers the library: every public module has its API reference, every
example its page in the site's navigation (`.ci/run` builds the site with warnings as errors)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.test_docstrings import public_modules

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def test_every_public_module_is_in_the_api_reference():
    rendered = set()
    for page in (DOCS / "reference").glob("*.md"):
        rendered |= set(re.findall(r"^::: (\S+)$", page.read_text(encoding="utf-8"), re.M))
    assert set(public_modules()) <= rendered, set(public_modules()) - rendered


def test_every_example_has_a_page_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    for script in sorted((ROOT / "examples").glob("[0-9]*.py")):
        page = DOCS / "examples" / f"{script.stem}.md"
        assert page.is_file(), f"{script.name} has no page {page.relative_to(ROOT)}"
        assert f"examples/{script.stem}.md" in nav, f"{page.name} is not in mkdocs.yml's nav"
        assert f'--8<-- "examples/{script.name}"' in page.read_text(encoding="utf-8")


def test_the_getting_started_snippet_prints_what_the_page_says(capsys):
    page = (DOCS / "getting-started.md").read_text(encoding="utf-8")
    section = page[page.index("## From Python") :]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    shown = re.search(r"It prints.*?```text\n(.*?)```", section, re.S).group(1)
    exec(compile(code, "getting-started.md", "exec"), {})
    assert capsys.readouterr().out == shown


def test_the_api_reference_lists_a_pydantic_models_fields():
    # mkdocs.yml loads griffe_pydantic; the same extension must see the fields.
    griffe = pytest.importorskip("griffe", reason='the docs extra: pip install -e ".[docs]"')
    assert "griffe_pydantic" in (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    extensions = griffe.load_extensions("griffe_pydantic")
    module = griffe.load("articula.planning.baornn_improved", search_paths=[ROOT / "src"],
                         extensions=extensions)  # fmt: skip
    params = module["ImprovedParams"]
    assert "pydantic-model" in params.labels
    fields = {name for name, member in params.members.items() if "pydantic-field" in member.labels}
    assert {"pairs", "short_antenna", "yield_distance"} <= fields


def test_the_your_arm_page_runs_and_prints_what_it_says(capsys, tmp_path, monkeypatch):
    page = (DOCS / "guides" / "your-arm.md").read_text(encoding="utf-8")
    code = re.search(r"```python\n(.*?)```", page, re.S).group(1)
    shown = re.search(r"It prints.*?```text\n(.*?)```", page, re.S).group(1)
    monkeypatch.chdir(tmp_path)  # it writes its mesh, rock.stl, where it runs
    exec(compile(code, "your-arm.md", "exec"), {})
    assert capsys.readouterr().out == shown
    assert (tmp_path / "rock.stl").is_file()


def test_the_arm_tracking_pages_code_prints_what_its_comment_says(capsys):
    """Issue 48: the comment had gone stale (40.1 mm where the code printed another number)."""
    page = (DOCS / "guides" / "arm-tracking.md").read_text(encoding="utf-8")
    section = page[page.index("## From Python") :]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    shown = re.search(r"^# (rms .*)$", code, re.M).group(1)
    exec(compile(code, "arm-tracking.md", "exec"), {})
    printed = capsys.readouterr().out.strip()
    # the errors and clearance are the run's own; the time per period is the machine's
    assert printed.rsplit(", ", 1)[0] == shown.rsplit(", ", 1)[0], printed


def test_the_arm_tracking_pages_scene_check_shows_what_it_prints(capsys):
    """Every line the page shows of `articula scene check` is printed (rich wraps long lines
    to the width of a pipe: compared word by word)."""
    from articula.cli import main

    page = (DOCS / "guides" / "arm-tracking.md").read_text(encoding="utf-8")
    block = re.search(r"```text\n\$ articula scene check (.*?)\n(.*?)```", page, re.S)
    scene, q = re.fullmatch(r'(\S+) --q "(.*)"', block.group(1)).groups()
    main(["scene", "check", str(ROOT / scene), "--q", q])
    printed = " ".join(capsys.readouterr().out.split())
    for line in block.group(2).splitlines():
        assert " ".join(line.split()) in printed, line
