"""Chapter 1's report section: formatting only, and what the full section holds."""

from __future__ import annotations

import json
import re

import pytest

from articula.book.ch1 import report
from articula.book.ch1.analysis import AVERAGED
from articula.book.ch1.book_values import BOOK_RUNS, METHODS, SCENES, SNAPSHOTS
from articula.book.ch1.study import Ch1Results

# Every test here reads the chapter-1 study run once (conftest.py's `section`, about 25 s);
# chapter 4's run (tests/book/conftest.py) stands for a study in the default step.
pytestmark = pytest.mark.slow

HEADINGS = (
    "### Figs. 1.4-1.12: the faithful BAORNN (Algorithm 1)",
    "### All methods on all scenes",
)


def _made_up() -> tuple[dict, dict]:
    metrics = {r.name: {k: 1e-3 for k in AVERAGED} for r in BOOK_RUNS}
    row = {**{k: 2e-3 for k in AVERAGED}, "runs": 1, "rms_error_range": [2e-3, 2e-3]}
    table = {s: {m: dict(row) for m in METHODS} for s in SCENES}
    return metrics, table


def test_the_markdown_formats_made_up_numbers_without_running_anything(section):
    metrics, table = _made_up()
    settings = {"d_min": 0.002, "pairs": 3, "short_antenna": 0.25, "gain": 20.0,
                "repulsion": 0.02, "influence": 0.15, "safety": 0.03, "dt": 0.01,
                "iterations_per_step": 10, "c1": 0.3, "c2": 0.5,
                "beta": 1.0, "settle": 5.0}  # fmt: skip
    md = report.markdown(Ch1Results(metrics, {}, {}, settings), table, full=False)
    assert "d_min = 0.002 m" in md and "K = 20/s" in md
    assert all(h in md for h in HEADINGS)
    for run in BOOK_RUNS:
        assert f"| {run.title} | 1.00 | 1.00 | 1.0 (1.0) |" in md
        assert f"![{run.title}](ch1/{run.name}_paths.png)" in md
    assert md.count("| rectangle | ") == len(METHODS)  # no scene given: no scene-table row
    assert "seed 0 (quick)" in md and "Collisions (" in md


def test_the_headings_come_in_order_on_their_own_lines(section):
    md = section["section"].markdown
    positions = [md.index(h) for h in HEADINGS]
    assert positions == sorted(positions)
    assert all(f"\n{h}\n" in f"\n{md}" for h in HEADINGS)
    assert "claims" not in md.lower().split("###")[-1][:40]  # the claims block is shared


def test_every_figure_the_markdown_links_exists_under_out(section):
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", section["section"].markdown)
    # Paths and time series for every book run, snapshots for Figs. 1.7 and 1.10.
    assert len(links) == 2 * len(BOOK_RUNS) + len(SNAPSHOTS)
    assert len(set(links)) == len(links)
    for link in links:
        assert link.endswith(".png") and link.startswith("ch1/"), link
        path = section["report"] / link
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", link


def test_the_markdown_has_no_nan_or_inf(section):
    md = section["section"].markdown
    assert not re.search(r"\b(nan|inf)\b", md, flags=re.IGNORECASE)


def test_the_data_holds_runs_and_comparison_and_the_claims_are_booleans(section):
    result = section["section"]
    assert set(result.data) == {"runs", "comparison"}
    assert set(result.data["comparison"]) == set(SCENES)
    assert len(result.claims) == 8
    assert {c.verdict for c in result.claims} <= {"reproduced", "not reproduced"}
    json.dumps(result.data, allow_nan=False)  # what `reproduce --json` must be able to print
