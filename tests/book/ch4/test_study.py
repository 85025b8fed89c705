"""Chapter 4's study: model numbers and, run once in quick mode, runs, figures and report."""

from __future__ import annotations

import re
import struct
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from articula.book.ch4 import analysis, study
from articula.book.ch4.book_values import FIGURES
from articula.book.study import packaged, run_folder
from articula.plants.dc_motor import TABLE_4_1, TABLE_4_2, steady_state
from articula.runs import records
from articula.validation import load_toml
from tests.helpers import hidden_files

PNGS = ["fig4_3", *FIGURES, "bandwidth"]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
CLAIMS = [analysis.OMEGA_C, analysis.PER_VOLT, analysis.RISE_TIME, analysis.TRACKS,
          analysis.AMPLITUDE_FALLS, analysis.LAG_GROWS, analysis.FEEDBACK_RISE,
          analysis.CURRENT_RISE, analysis.FILTER_COSTS, analysis.LESS_NOISE,
          analysis.LESS_BANDWIDTH]  # fmt: skip


@pytest.fixture
def ch4(reproduced_ch4):
    """The quick `reproduce ch4` run shared by the book's tests: (out, chapters.ch4)."""
    out, summary = reproduced_ch4
    return out, summary["chapters"]["ch4"]


# ----- model numbers and the linearised loop, in process ----------------------------------------


def test_model_numbers_follow_eqs_4_8_to_4_11():
    m = study.model_numbers()
    assert (m.omega_per_volt, m.current_per_volt) == steady_state(TABLE_4_1, 1.0)
    assert m.omega_at_supply == pytest.approx(12 * m.omega_per_volt, rel=1e-12)
    assert m.current_at_supply == pytest.approx(12 * m.current_per_volt, rel=1e-12)
    assert m.denominator == pytest.approx(TABLE_4_1.b * TABLE_4_1.R + TABLE_4_1.K**2)
    assert m.omega_c == pytest.approx((12.0 - 1.0 * TABLE_4_2.R) / TABLE_4_2.K, rel=1e-12)
    assert m.stall_current == pytest.approx(12.0 / TABLE_4_2.R)
    assert m.no_load_speed == pytest.approx(12.0 / TABLE_4_2.K)
    # A braking torque (τ_ex < 0) raises the steady-state current, Eq. (4.10).
    assert m.current_with_load > m.current_at_supply


def test_simulation_settles_at_the_closed_form_steady_state():
    omega, current = study.simulated_steady_state(TABLE_4_1, 12.0, 120.0)
    want = steady_state(TABLE_4_1, 12.0)
    assert omega == pytest.approx(want[0], rel=1e-6)
    assert current == pytest.approx(want[1], rel=1e-6)


def test_linearised_unfiltered_loop_is_stable_with_a_finite_bandwidth():
    stable, wb = study.linear_bandwidth(1)
    assert stable
    assert 1.0 < wb < 100.0


# ----- the whole chapter, quick mode --------------------------------------------------------------


def test_summary_keeps_the_model_numbers_and_names_every_claim(ch4):
    _, data = ch4
    assert data["omega_c"] == pytest.approx(8.1382, abs=1e-4)
    assert (data["omega_ss_per_volt"], data["i_ss_per_volt"]) == steady_state(TABLE_4_1, 1.0)
    assert list(data["claims"]) == CLAIMS
    assert all(isinstance(v, bool) for v in data["claims"].values())
    assert [c["name"] for c in data["claims_detail"]] == CLAIMS
    assert data["claims"][analysis.OMEGA_C] is True


def test_summary_has_every_figure_run_and_filter_order(ch4):
    _, data = ch4
    assert list(data["runs"]) == list(FIGURES)
    assert [data["runs"][n]["k"] for n in FIGURES] == [1, 1, 1, 50, 50]
    assert [r["k"] for r in data["bandwidth"]] == [1, 4, 16, 64, 256]


def test_fig_4_7_loses_amplitude_against_fig_4_6(ch4):
    _, data = ch4
    a6 = data["runs"]["fig4_6"]["amplitude_ratio"]
    a7 = data["runs"]["fig4_7"]["amplitude_ratio"]
    assert 0 < a7 < a6


def test_report_has_the_chapter_4_section(ch4):
    out, _ = ch4
    text = (out / "report.md").read_text()
    assert "## Chapter 4: DC motor torque (current) control" in text
    for heading in (
        "### Motor model (Sect. 4.2) and critical speed (Sect. 4.3.2)",
        "### Fig. 4.3: current against speed at 12 V",
        "### Figs. 4.5-4.9: PI + feed-forward current control on the dual-motor rig",
        "### The chapter's question: bandwidth against filter order, and what it buys",
    ):
        assert heading in text, heading
    assert re.search(r"\| ω_c at 12 V and 1 A, Table 4\.2 \[rad/s\] \| 8\.1382 \| 8\.1382 \|", text)
    assert "src/articula/book/ch4/configs/<fig>.toml" in text
    assert "omega_c matches the book" in text.split("## Chapter 4")[1]
    # No number in the report came out as NaN or infinity.
    assert not re.search(r"\b(nan|inf)\b", text, flags=re.IGNORECASE)


def _png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC, path
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


@pytest.mark.parametrize("name", PNGS)
def test_figures_are_png_files(ch4, name):
    out, _ = ch4
    width, height = _png_size(out / "ch4" / f"{name}.png")
    assert width > 100 and height > 100


def test_figure_runs_and_bandwidth_sweep_are_kept(ch4):
    out, _ = ch4
    for name in FIGURES:
        folder = run_folder(out / "ch4" / study.RUNS, load_toml(packaged("ch4", f"{name}.toml")))
        assert records.is_finished(folder), name
        assert records.read_record(folder)["experiment"] == "motor.current"
    sweep = out / "ch4" / study.SWEEP
    results = pq.read_table(sweep / "results.parquet")
    assert results.num_rows == 5 * 10  # quick: 5 filter orders x 10 frequencies
    assert sorted(set(results.column("controller.filter_order").to_pylist())) == [1, 4, 16, 64, 256]
    assert (out / "ch4" / "bandwidth_sweep.toml").is_file()
    assert hidden_files(out) == []
