"""`articula reproduce`: one JSON object, a report whose image links exist, unknown chapters
refused before anything is written. The chapter run is ch4, the quickest."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from articula.book.reproduce import reproduce
from articula.cli import main
from articula.errors import ConfigError


@pytest.fixture
def ch4(reproduced_ch4):
    """The quick `reproduce ch4` run shared by the book's tests: (out, summary)."""
    return reproduced_ch4


def test_summary_is_one_json_object(ch4):
    out, summary = ch4
    assert summary["report"] == str(out / "report.md")
    assert list(summary["chapters"]) == ["ch4"]
    chapter = summary["chapters"]["ch4"]
    assert isinstance(chapter["claims"], dict) and isinstance(chapter["claims_detail"], list)
    assert summary["mode"] == "quick"
    assert summary["wall_time_s"] >= 0


def test_report_starts_with_the_mode_and_versions(ch4):
    out, _ = ch4
    text = (out / "report.md").read_text()
    assert text.startswith("# articula: reproduction of the book's experiments")
    assert "Mode: quick." in text
    assert "articula" in text.split("Versions:")[1].splitlines()[0]
    assert "### The chapter's claims against our runs" in text


def test_every_image_link_of_the_report_exists(ch4):
    out, _ = ch4
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", (out / "report.md").read_text())
    assert links
    for link in links:
        assert (out / link).is_file(), link
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*.png")) == sorted(links)


# ----- unknown chapters ---------------------------------------------------------------------------


def test_unknown_chapter_is_one_line_exit_2(cli, tmp_path, assert_one_line_error):
    out = tmp_path / "report"
    proc = cli("reproduce", "ch5", "--out", out, "--json")
    assert proc.stdout == ""
    assert_one_line_error(proc, "chapter", "ch5")
    assert not out.exists()


@pytest.mark.parametrize("chapter", ["ch0", "ch5", "ch8", "ch9"])
def test_unknown_chapter_in_process(capsys, tmp_path, chapter):
    out = tmp_path / "report"
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", chapter, "--out", str(out), "--json"])
    assert exc.value.code == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and "chapter" in lines[0] and chapter in lines[0], captured.err
    assert not out.exists()


def test_unknown_chapter_without_json_is_one_line(cli, tmp_path, assert_one_line_error):
    proc = cli("reproduce", "ch5", "--out", tmp_path / "report")
    assert_one_line_error(proc, "chapter", "ch5")


def test_reproduce_rejects_an_unknown_chapter_before_writing(tmp_path: Path):
    with pytest.raises(ConfigError) as exc:
        reproduce("ch9", tmp_path / "report")
    assert exc.value.field == "chapter"
    assert "ch4" in exc.value.problem
    assert not (tmp_path / "report").exists()


def test_the_claims_table_counts_each_chapters_verdicts(reproduced_ch4):
    from articula.cli.book import verdict_counts

    _, summary = reproduced_ch4
    details = summary["chapters"]["ch4"]["claims_detail"]
    counts = [int(c) for c in verdict_counts(details)]
    assert sum(counts) == len(details) > 0
    assert counts[0] == sum(summary["chapters"]["ch4"]["claims"].values())  # reproduced


@pytest.mark.slow
def test_each_chapter_is_announced_as_a_stage(tmp_path):
    stages: list[str] = []
    reproduce("ch4", tmp_path / "report", stage=stages.append)
    assert stages == ["ch4, 1 of 1"]
