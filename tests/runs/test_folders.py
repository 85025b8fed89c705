"""Output folders: refused when foreign, held by one writer, cleaned only by their holder."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from articula.errors import ConfigError, ResourceError
from articula.runs import folders
from articula.runs.folders import check_out, claimed, foreign_entries, temporary_name_of


def _write(folder, *names):
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / name).write_text("x")


def test_temporary_names_are_recognised_by_their_shape():
    assert temporary_name_of(".record.json.ab12_x9z.tmp") == "record.json"
    assert temporary_name_of(".notes.tmp") is None
    assert temporary_name_of("record.json") is None


@pytest.mark.parametrize(
    ("kind", "ours", "foreign"),
    [
        ("run", ["config.toml", "record.json", ".trace.parquet.abcdefgh.tmp"], ["notes.txt"]),
        ("sweep", ["results.parquet"], ["data.csv"]),
        ("report", ["report.md", "ch1"], ["thesis.tex"]),
    ],
)
def test_only_files_articula_writes_count_as_its_own(tmp_path, kind, ours, foreign):
    _write(tmp_path / "f", *[n for n in ours if n != "ch1"])
    if "ch1" in ours:
        (tmp_path / "f" / "ch1").mkdir()
    assert foreign_entries(tmp_path / "f", kind) == []
    _write(tmp_path / "f", *foreign)
    assert foreign_entries(tmp_path / "f", kind) == foreign


def test_a_sweep_folder_with_a_foreign_file_inside_a_run_folder_is_foreign(tmp_path):
    _write(tmp_path / "s" / "0123456789ab", "record.json")
    assert foreign_entries(tmp_path / "s", "sweep") == []
    _write(tmp_path / "s" / "0123456789ab", "mine.txt")
    assert foreign_entries(tmp_path / "s", "sweep") == ["0123456789ab"]


def test_a_foreign_folder_is_refused_naming_what_is_there_and_force_accepts_it(tmp_path):
    _write(tmp_path / "out", "thesis.tex")
    with pytest.raises(ConfigError) as err:
        check_out(tmp_path / "out", "run")
    assert err.value.field == "--out" and "thesis.tex" in err.value.problem
    assert "--force" in err.value.problem
    check_out(tmp_path / "out", "run", force=True)


def test_a_file_in_the_way_is_refused(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(ConfigError, match="is a file"):
        check_out(tmp_path / "f", "run")
    with pytest.raises(ConfigError, match="is a file"):
        check_out(tmp_path / "f" / "sub", "run")


def test_a_newline_in_a_path_stays_one_line_in_the_message(tmp_path):
    path = tmp_path / "a\nb"
    path.write_text("x")
    with pytest.raises(ConfigError) as err:
        check_out(path, "run")
    assert "\n" not in str(err.value) and "a\\nb" in str(err.value)


def test_the_holder_removes_only_articulas_stale_temporaries(tmp_path):
    _write(tmp_path / "run", "config.toml", ".config.toml.k1ll3d00.tmp")
    _write(tmp_path / "run", "..hidden.tmp")  # not ours: --force keeps it
    with claimed(tmp_path / "run", "run", force=True):
        assert sorted(os.listdir(tmp_path / "run")) == ["..hidden.tmp", "config.toml"]


def test_a_second_writer_is_refused_naming_the_holder(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c",
         "import sys, time; from pathlib import Path; from articula.runs.folders import claimed\n"
         "with claimed(Path(sys.argv[1]), 'sweep'):\n    print('held', flush=True); time.sleep(60)",
         str(out)],
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(ResourceError) as err, claimed(out, "sweep"):
            pass
        message = str(err.value)
        assert f"pid {holder.pid}" in message and "another process" in message
    finally:
        holder.kill()
        holder.wait()
    with claimed(out, "sweep"):  # the kernel dropped the lock when its holder died
        pass


def test_the_holder_is_unknown_without_a_lock(tmp_path):
    assert folders.holder(tmp_path) == "unknown"
