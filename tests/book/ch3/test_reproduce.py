"""`articula reproduce ch3`: the whole chapter once in quick mode, its JSON, report and figures."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from articula.book.ch3.book_values import CLAIM_BOOK, CLAIM_GROWS

# The whole chapter takes about 20 s; chapter 4's run (tests/book/conftest.py) stands for
# `articula reproduce` in the default step.
pytestmark = pytest.mark.slow

KEYS = {"delta", "peak_deg", "settling_s", "overshoot_pct", "open_ms", "claims", "search"}


@pytest.fixture(scope="module")
def chapter(cli, one_json, tmp_path_factory) -> tuple[dict[str, Any], Path]:
    """chapters.ch3 of `reproduce ch3 --json` and the output folder."""
    out = tmp_path_factory.mktemp("reproduce_ch3")
    proc = cli("reproduce", "ch3", "--out", out, "--json")
    assert proc.returncode == 0, proc.stderr
    return one_json(proc.stdout)["chapters"]["ch3"], out


def test_json_keeps_todays_keys(chapter):
    ch3, _ = chapter
    assert set(ch3) >= KEYS
    assert set(ch3["search"]) == {"book_timing", "timed", "side_30"}
    assert set(ch3["search"]["side_30"]) == {"delta", "start", "length", "settling_s",
                                             "evaluations"}  # fmt: skip


def test_json_delta_sweep_columns(chapter):
    ch3, _ = chapter
    n = len(ch3["delta"])
    assert n >= 5 and ch3["delta"][0] == 0.0
    assert len(ch3["peak_deg"]) == len(ch3["settling_s"]) == len(ch3["open_ms"]) == n
    assert all(isinstance(x, float) for x in ch3["peak_deg"] + ch3["settling_s"])
    assert all(x == round(x, 6) for x in ch3["settling_s"])  # sample instants, no float noise
    assert 18.0 <= ch3["peak_deg"][0] <= 20.0


def test_json_claims_by_todays_names(chapter):
    ch3, _ = chapter
    assert set(ch3["claims"]) == {CLAIM_GROWS, CLAIM_BOOK}
    assert all(isinstance(v, bool) for v in ch3["claims"].values())
    assert [c["name"] for c in ch3["claims_detail"]] == [CLAIM_GROWS, CLAIM_BOOK]


def test_report_has_the_computed_what_ifs_and_the_claims_block(chapter):
    _, out = chapter
    text = (out / "report.md").read_text()
    assert "## Chapter 3" in text
    # The assumed valve constants' sensitivity and the solenoid-time flags are computed.
    assert "| orifice 0.5 mm |" in text and "| flow_transition 5000 Pa |" in text
    assert "† Open time below 10 ms" in text
    assert f"{CLAIM_GROWS}. Book:" in text and f"{CLAIM_BOOK}. Book:" in text


def test_figures_and_sweep_files_are_written(chapter):
    _, out = chapter
    for name in ("fig3_7.png", "timing.png", "search.png", "delta_sweep.toml", "timing_sweep.toml"):
        assert (out / "ch3" / name).is_file()
