"""Chapter 1's study: every run planned once through the shared runner, resumable."""

from __future__ import annotations

import tomllib

import pyarrow.parquet as pq
import pytest

from articula.book.ch1.book_values import (
    BOOK_RUNS,
    FULL_SEEDS,
    METHODS,
    SCENES,
    STOCHASTIC,
    UNGUARDED,
    slug,
)
from articula.book.ch1.study import RUNS, SWEEP, comparison_runs, plan_config, scene_path
from articula.book.study import Study, read_metrics, run_folder
from articula.runs import records
from articula.runs.runner import normalized
from articula.runs.sweep import expand_sweep


def _names() -> list[str]:
    return [r.name for r in (*BOOK_RUNS, *comparison_runs(False))]


@pytest.mark.slow
def test_every_run_was_planned_once_shortened_and_written(section):
    names = _names()
    assert sorted(section["configs"]) == sorted(names)
    assert len(names) == len(BOOK_RUNS) + len(SCENES) * (len(METHODS) - 1)
    folders = sorted(p.name for p in (section["out"] / RUNS).iterdir() if p.is_dir())
    assert len(folders) == len(names)
    for name, config in section["configs"].items():
        folder = run_folder(section["out"] / RUNS, config)
        assert records.is_finished(folder), name
        assert pq.read_table(folder / records.TRACE).num_rows == 150  # 1.5 s at 10 ms
        assert records.read_record(folder)["metrics"]["settle_s"] == 1.0
    done = [d for d, _ in section["ticks"]]
    assert done == sorted(done) and done[-1] == len(names)
    assert {total for _, total in section["ticks"]} == {len(names)}


@pytest.mark.slow
def test_the_study_is_written_as_a_sweep_file_of_its_configs(section):
    spec = tomllib.loads((section["out"] / SWEEP).read_text())
    assert len(expand_sweep(spec)) == len(_names())


@pytest.mark.slow
def test_running_the_study_again_recomputes_nothing(section, monkeypatch):
    from articula.book.ch1 import study

    written = {p: p.stat().st_mtime_ns for p in (section["out"] / RUNS).glob("*/record.json")}
    monkeypatch.setattr(study, "plan_config", lambda run: section["configs"][run.name])
    study.run_study(Study(section["out"]))
    after = {p: p.stat().st_mtime_ns for p in (section["out"] / RUNS).glob("*/record.json")}
    assert after == written


@pytest.mark.slow
def test_the_book_runs_without_a_penalty_also_drop_d_min(section):
    # Sect. 1.4.1 runs Λ = 0 "ignoring the 2nd constraint": d_min = 0 as well.
    for run in BOOK_RUNS:
        folder = run_folder(section["out"] / RUNS, section["configs"][run.name])
        planner = tomllib.loads((folder / records.CONFIG).read_text())["planner"]
        if run.name in UNGUARDED:
            assert planner["lambda_weight"] == 0.0 and planner["d_min"] == 0.0, run.name
        else:
            assert planner["lambda_weight"] > 0 and planner["d_min"] > 0, run.name


@pytest.mark.slow
def test_the_data_runs_are_the_records_of_the_book_runs(section):
    runs = section["section"].data["runs"]
    assert set(runs) == {r.name for r in BOOK_RUNS}
    for name, metrics in runs.items():
        assert metrics == read_metrics(section["out"] / RUNS, section["configs"][name])


def test_a_run_config_lifts_the_tolerance_and_puts_its_seed_at_the_top():
    run = next(r for r in comparison_runs(True) if r.overrides.get("seed") == FULL_SEEDS[-1])
    config = normalized(plan_config(run))
    assert config["seed"] == FULL_SEEDS[-1] and "seed" not in config["planner"]
    assert config["planner"]["tolerance"] == 1e3
    assert config["experiment"] == "baornn.plan"


def test_full_mode_runs_every_seed_of_the_stochastic_methods_only():
    runs = comparison_runs(full=True)
    for scene in SCENES:
        for method in METHODS:
            prefix = f"{slug(scene)}_{method}"
            count = sum(r.name == prefix or r.name.startswith(prefix + "_seed") for r in runs)
            if method == "baornn":  # its seed 0 is the scene's book run
                assert count == len(FULL_SEEDS) - 1
            else:
                assert count == (len(FULL_SEEDS) if method in STOCHASTIC else 1), method


def test_every_scene_is_a_packaged_file_with_a_penalty_and_d_min():
    for scene in SCENES:
        data = tomllib.loads(scene_path(scene).read_text())
        assert data["planner"]["d_min"] > 0 and data["planner"]["lambda_weight"] > 0, scene
