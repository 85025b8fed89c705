"""What a chapter's study is given: sizes, packaged files, and sweeps through the runner."""

from __future__ import annotations

from articula.book.study import Study, packaged, read_metrics, read_trace, run_folder
from articula.runs import records

TINY = {"experiment": "motor.current", "duration": 0.2, "settle": 0.1}


def test_the_size_names_the_packaged_sweep_files():
    assert Study(out=packaged("ch4", "."), full=False).size == "quick"
    assert packaged(
        "ch4", f"bandwidth_{Study(packaged('ch4', '.'), full=True).size}.toml"
    ).is_file()


def test_a_sweep_reports_progress_from_where_the_chapter_is(tmp_path):
    ticks = []
    study = Study(tmp_path, progress=lambda done, total: ticks.append((done, total)))
    table = study.sweep([TINY, {**TINY, "seed": 1}], "s", done=5, total=9)
    assert table.num_rows == 2
    assert ticks[0] == (5, 9) and ticks[-1] == (7, 9)


def test_a_partial_config_finds_its_run_folder_metrics_and_trace(tmp_path):
    Study(tmp_path).sweep([TINY], "s")
    folder = run_folder(tmp_path / "s", TINY)
    assert records.is_finished(folder)
    assert read_metrics(tmp_path / "s", TINY) == records.read_record(folder)["metrics"]
    assert read_trace(tmp_path / "s", TINY)["t"].size == 200
