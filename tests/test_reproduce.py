"""`articula reproduce`: the chapter-4 report and its figures; unbuilt chapters are refused."""

from __future__ import annotations

import re
import struct
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from articula.cli import main
from articula.errors import ConfigError
from articula.experiments import records
from articula.experiments.reproduce import reproduce

FIGURES = ["fig4_3", "fig4_5", "fig4_6", "fig4_7", "fig4_8", "fig4_9", "bandwidth"]
RUNS = ["fig4_5", "fig4_6", "fig4_7", "fig4_8", "fig4_9"]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def ch4(cli, one_json, tmp_path_factory):
    """`articula reproduce ch4 --out DIR --json` (quick mode), run once for the module."""
    out = tmp_path_factory.mktemp("reproduce") / "report"
    # The linearised bandwidth study does thousands of small dense solves; multithreaded
    # OpenBLAS on a busy 2-core machine makes that many times slower, so pin it to one thread.
    proc = cli("reproduce", "ch4", "--out", out, "--json", env={"OPENBLAS_NUM_THREADS": "1"})
    assert proc.returncode == 0, proc.stderr
    return out, one_json(proc.stdout)


def test_summary_is_one_json_object(ch4):
    out, summary = ch4
    assert summary["report"] == str(out / "report.md")
    assert list(summary["chapters"]) == ["ch4"]
    assert summary["chapters"]["ch4"]["omega_c"] == pytest.approx(8.1382, abs=1e-4)
    assert summary["mode"] == "quick"
    assert summary["wall_time_s"] >= 0


def test_report_has_the_chapter_4_section(ch4):
    out, _ = ch4
    text = (out / "report.md").read_text()
    assert text.startswith("# articula: reproduction of the book's experiments")
    assert "Mode: quick." in text
    assert "## Chapter 4: DC motor torque (current) control" in text
    for heading in (
        "### Motor model (Sect. 4.2) and critical speed (Sect. 4.3.2)",
        "### Fig. 4.3: current against speed at 12 V",
        "### Figs. 4.5-4.9: PI + feed-forward current control on the dual-motor rig",
        "### The chapter's question: bandwidth against filter order, and what it buys",
    ):
        assert heading in text, heading
    # The critical speed for Table 4.2 at 12 V and 1 A, as in the book.
    assert re.search(r"\| ω_c at 12 V and 1 A, Table 4\.2 \[rad/s\] \| 8\.1382 \| 8\.1382 \|", text)
    assert "articula" in text.split("Versions:")[1].splitlines()[0]
    # No number in the report came out as NaN or infinity.
    assert not re.search(r"\b(nan|inf)\b", text, flags=re.IGNORECASE)


def _png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC, path
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


@pytest.mark.parametrize("name", FIGURES)
def test_figures_are_png_files(ch4, name):
    out, _ = ch4
    width, height = _png_size(out / "ch4" / f"{name}.png")
    assert width > 100 and height > 100


def test_every_image_link_of_the_report_exists(ch4):
    out, _ = ch4
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", (out / "report.md").read_text())
    assert sorted(Path(link).stem for link in links) == sorted(FIGURES)
    for link in links:
        assert (out / link).is_file(), link


def test_figure_runs_and_bandwidth_sweep_are_kept(ch4):
    out, _ = ch4
    for name in RUNS:
        folder = out / "ch4" / "runs" / name
        assert records.is_finished(folder), name
        assert records.read_record(folder)["experiment"] == "motor.current"
    sweep = out / "ch4" / "bandwidth_sweep"
    results = pq.read_table(sweep / "results.parquet")
    assert results.num_rows == 5 * 10  # quick: 5 filter orders x 10 frequencies
    assert sorted(set(results.column("controller.filter_order").to_pylist())) == [1, 4, 16, 64, 256]
    assert (out / "ch4" / "bandwidth_sweep.toml").is_file()
    assert [p for p in out.rglob("*") if p.name.startswith(".")] == []


def test_fig_4_7_loses_amplitude_against_fig_4_6(ch4):
    out, _ = ch4
    runs = out / "ch4" / "runs"
    a6 = records.read_record(runs / "fig4_6")["metrics"]["amplitude_ratio"]
    a7 = records.read_record(runs / "fig4_7")["metrics"]["amplitude_ratio"]
    assert 0 < a7 < a6


# ----- chapters that cannot be reproduced yet --------------------------------------------------


def test_unknown_chapter_is_one_line_exit_2(cli, tmp_path, assert_one_line_error):
    out = tmp_path / "report"
    proc = cli("reproduce", "ch5", "--out", out, "--json")
    assert proc.stdout == ""
    assert_one_line_error(proc, "chapter", "ch5")
    assert not out.exists()


@pytest.mark.parametrize("chapter", ["ch0", "ch5", "ch8", "ch9"])
def test_unbuilt_chapter_in_process(capsys, tmp_path, chapter):
    out = tmp_path / "report"
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", chapter, "--out", str(out), "--json"])
    assert exc.value.code == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and "chapter" in lines[0] and chapter in lines[0], captured.err
    assert not out.exists()


def test_unbuilt_chapter_without_json_is_one_line(cli, tmp_path, assert_one_line_error):
    proc = cli("reproduce", "ch5", "--out", tmp_path / "report")
    assert_one_line_error(proc, "chapter", "ch5")


def test_reproduce_rejects_unbuilt_chapter_before_writing(tmp_path):
    with pytest.raises(ConfigError) as exc:
        reproduce("ch9", tmp_path / "report")
    assert exc.value.field == "chapter"
    assert "ch4" in exc.value.problem
    assert not (tmp_path / "report").exists()
