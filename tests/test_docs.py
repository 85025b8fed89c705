"""The documentation site covers the library: every public module has its API reference, every
example its page in the site's navigation (`.ci/run` builds the site with warnings as errors)."""

from __future__ import annotations

import re
from pathlib import Path

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
