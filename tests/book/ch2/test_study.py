"""book/ch2/study.py: the controllers it compares, and `articula reproduce ch2` end to end."""

import re
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from articula.book.ch2.book_values import CLAIMS, CONTROLLERS, FREQUENCIES
from articula.book.ch2.study import controllers
from articula.runs import records
from articula.runs.runner import RESULTS
from articula.runs.sweep import expand_sweep
from articula.validation import load_toml

FIGURES = ["fig2_5", "fig2_6", "fig2_7", "fig2_8", "fig2_9", "fig2_10"]


def test_controllers_take_the_tuned_gains(made_up):
    tables = controllers(made_up().tuning)
    assert list(tables) == list(CONTROLLERS)
    assert tables["ordinary-manual"] == {"name": "ordinary-manual", "schedule": "constant",
                                         "gains": [[1.27, 2.56, 0.0]]}  # fmt: skip
    assert tables["ordinary-auto"]["gains"] == [[0.87, 5.44, 0.04]]
    fuzzy = tables["fuzzy-auto"]
    assert fuzzy["schedule"] == "fuzzy" and fuzzy["points_deg"] == [15.0, 45.0, 75.0]
    assert fuzzy["gains"] == [[0.64, 1.21, 0.165], [0.46, 2.98, 0.09], [0.91, 5.08, 0.1]]
    assert tables["piecewise-manual"]["gains"][0] == [1.9, 0.76, 0.0]


# ----- `articula reproduce ch2` --------------------------------------------------------------


@pytest.fixture(scope="module")
def ch2(cli, one_json, tmp_path_factory):
    """`articula reproduce ch2 --out DIR --json` (quick mode), run once for the module."""
    out = tmp_path_factory.mktemp("reproduce") / "report"
    proc = cli("reproduce", "ch2", "--out", out, "--json", "--workers", "2")
    assert proc.returncode == 0, proc.stderr
    return out, one_json(proc.stdout)


@pytest.mark.slow
def test_json_has_table_2_3(ch2):
    data = ch2[1]["chapters"]["ch2"]
    assert sorted(data["table_2_3"]) == sorted(CONTROLLERS)
    for rows in data["table_2_3"].values():
        assert list(rows) == [f"{f:g}" for f in FREQUENCIES]
        for median, q1, q3 in rows.values():
            assert 0 <= q1 <= median <= q3 <= 90


@pytest.mark.slow
def test_json_has_table_2_2(ch2):
    data = ch2[1]["chapters"]["ch2"]
    assert sorted(data["table_2_2"]) == ["auto", "manual"]
    assert sorted(data["table_2_2"]["auto"]) == ["15", "45", "75", "sequence"]
    assert sorted(data["table_2_2"]["manual"]) == ["15", "45", "75", "90"]
    for gains in data["table_2_2"]["manual"].values():
        assert set(gains) == {"kp", "ki", "kd"} and min(gains.values()) >= 0


@pytest.mark.slow
def test_json_has_the_claims_by_name(ch2):
    data = ch2[1]["chapters"]["ch2"]
    assert set(data["claims"]) == set(CLAIMS) == {
        "automatic_beats_manual", "piecewise_fuzzy_beat_ordinary",
        "error_grows_with_frequency", "kd_zero_optimal",
    }  # fmt: skip
    assert all(isinstance(v, bool) for v in data["claims"].values())
    detail = {c["name"]: c for c in data["claims_detail"]}
    assert set(detail) == set(CLAIMS)
    for name, claim in detail.items():
        assert data["claims"][name] == (claim["verdict"] == "reproduced")


@pytest.mark.slow
def test_report_section_has_the_books_numbers_and_the_claims(ch2):
    text = (ch2[0] / "report.md").read_text()
    assert "## Chapter 2: PID control of a soft bending actuator (PneuNet)" in text
    assert "19.03" in text and "45.14" in text  # the book's Table 2.3 beside ours
    assert not re.search(r"\b(nan|inf)\b", text, flags=re.IGNORECASE)
    chapter = text.split("## Chapter 2")[1]
    assert len(re.findall(r"^- \*\*(?:Reproduced|Not reproduced|Inconclusive)\.\*\* ", chapter,
                          flags=re.MULTILINE)) == len(CLAIMS)  # fmt: skip


@pytest.mark.slow
def test_figures_are_written_and_linked(ch2):
    out = ch2[0]
    for name in FIGURES:
        assert (out / "ch2" / f"{name}.png").read_bytes()[:4] == b"\x89PNG"
    links = re.findall(r"!\[[^\]]*\]\((ch2/[^)]+)\)", (out / "report.md").read_text())
    assert sorted(Path(link).stem for link in links) == sorted(FIGURES)


@pytest.mark.slow
def test_the_sweep_file_beside_the_report_has_nothing_left_to_run(ch2):
    out = ch2[0] / "ch2"
    sweep = out / "table2_3_sweep"
    assert pq.read_table(sweep / RESULTS).num_rows == len(CONTROLLERS) * len(FREQUENCIES)
    configs = expand_sweep(load_toml(out / "table2_3_sweep.toml"))
    assert all(records.is_finished(sweep / records.config_hash(c)) for c in configs)
