"""`reproduce ch1`: the section's markdown, figures, numbers and claims on shortened runs."""

from __future__ import annotations

import dataclasses
import json
import re
import tomllib
from pathlib import Path
from typing import Any

import pyarrow.parquet as pq
import pytest

from articula.experiments import ch1_report
from articula.experiments.ch1_report import (
    BOOK_RUN_OF_SCENE,
    BOOK_RUNS,
    METHODS,
    SCENES,
    ch1_section,
    comparison_runs,
)

SHORT = {"duration": 1.5, "settle": 1.0}  # [s] of simulated time per run
HEADINGS = (
    "### Figs. 1.4-1.12: the faithful BAORNN (Algorithm 1)",
    "### All methods on all scenes",
    "### The chapter's claims against our runs",
)
UNGUARDED = ("fig1_4_rectangle", "fig1_4_circle", "fig1_11")  # the book's Λ = 0 runs
GUARDED = ("fig1_5", "fig1_6", "fig1_8", "fig1_9", "fig1_12")


@pytest.fixture(scope="module")
def section(tmp_path_factory) -> dict[str, Any]:
    """ch1_section in quick mode, one worker, every run cut to 1.5 s (settle 1 s)."""
    report = tmp_path_factory.mktemp("report")
    out = report / "ch1"  # reproduce() passes OUT/ch1; the markdown links are relative to OUT
    original = ch1_report.execute
    executed: list[str] = []

    def short(run):
        executed.append(run.name)
        return original(dataclasses.replace(run, overrides={**run.overrides, **SHORT}))

    ticks: list[tuple[int, int]] = []
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(ch1_report, "execute", short)
        markdown, data = ch1_section(out, False, 1, lambda done, total: ticks.append((done, total)))
    return {"report": report, "out": out, "markdown": markdown, "data": data,
            "executed": executed, "ticks": ticks}  # fmt: skip


def _runs() -> list[str]:
    return [r.name for r in (*BOOK_RUNS, *comparison_runs(False))]


def _record(section, name: str) -> dict[str, Any]:
    return json.loads((section["out"] / "runs" / name / "record.json").read_text())


def test_every_run_was_planned_once_shortened_and_written(section):
    names = _runs()
    assert sorted(section["executed"]) == sorted(names)
    assert len(names) == len(BOOK_RUNS) + len(SCENES) * (len(METHODS) - 1)
    for name in names:
        folder = section["out"] / "runs" / name
        assert (folder / "record.json").is_file(), name
        assert pq.read_table(folder / "trace.parquet").num_rows == 150  # 1.5 s at 10 ms
        assert _record(section, name)["metrics"]["settle_s"] == 1.0
    ticks = section["ticks"]
    assert [done for done, _ in ticks] == list(range(1, len(names) + 1))
    assert {total for _, total in ticks} == {len(names)}


def test_the_markdown_has_the_three_headings_in_order(section):
    md = section["markdown"]
    positions = [md.index(h) for h in HEADINGS]  # ValueError if one is missing
    assert positions == sorted(positions)
    assert all(f"\n{h}\n" in f"\n{md}" for h in HEADINGS)  # headings on their own lines


def test_every_figure_the_markdown_links_exists_under_out(section):
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", section["markdown"])
    # Paths and time series for every book run, snapshots for Figs. 1.7 and 1.10.
    assert len(links) == 2 * len(BOOK_RUNS) + 2
    assert len(set(links)) == len(links)
    for link in links:
        assert link.endswith(".png") and link.startswith("ch1/"), link
        path = section["report"] / link
        assert path.is_file(), link
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", link
        assert path.resolve().parent == section["out"].resolve()


def test_the_markdown_has_no_nan_or_inf(section):
    md = section["markdown"]
    assert not re.search(r"\b(nan|inf)\b", md, flags=re.IGNORECASE), re.findall(
        r".*\b(?:nan|inf)\b.*", md, flags=re.IGNORECASE
    )


def test_the_data_holds_runs_comparison_and_boolean_claims(section):
    data = section["data"]
    assert set(data) == {"runs", "comparison", "claims"}
    assert set(data["runs"]) == {r.name for r in BOOK_RUNS}
    for name, metrics in data["runs"].items():
        assert metrics == _record(section, name)["metrics"]
    assert set(data["comparison"]) == set(SCENES)
    for scene, methods in data["comparison"].items():
        assert set(methods) == set(METHODS), scene
    assert len(data["claims"]) >= 5
    assert all(type(ok) is bool for ok in data["claims"].values()), data["claims"]
    json.dumps(data, allow_nan=False)  # what `reproduce --json` must be able to print


def test_the_comparison_rows_are_the_runs_numbers(section):
    table, runs = section["data"]["comparison"], section["data"]["runs"]
    for scene, methods in table.items():
        for method, entry in methods.items():
            name = BOOK_RUN_OF_SCENE[scene] if method == "baornn" else None
            name = name or f"{scene.replace(' ', '_')}_{method}"
            metrics = runs[name] if method == "baornn" else _record(section, name)["metrics"]
            assert entry["runs"] == 1  # quick mode: seed 0 only
            for key in ("rms_error", "min_clearance", "min_clearance_settled", "collisions",
                        "collisions_settled"):  # fmt: skip
                assert entry[key] == pytest.approx(metrics[key], rel=1e-12), (scene, method, key)
            assert entry["rms_error_range"] == pytest.approx([metrics["rms_error"]] * 2)


def test_the_claims_follow_from_the_runs_numbers(section):
    runs, claims = section["data"]["runs"], section["data"]["claims"]

    def claim(start: str) -> bool:
        (ok,) = [ok for text, ok in claims.items() if text.startswith(start)]
        return ok

    assert claim("Λ = 0 collides") == all(runs[n]["collisions"] > 0 for n in UNGUARDED)
    assert claim("with Λ > 0") == all(runs[n]["collisions"] == 0 for n in GUARDED)
    assert claim("two obstacles") == (runs["fig1_12"]["min_clearance"] > 0.05)
    assert claim("Λ = 0 tracks within 1 mm") == all(runs[n]["rms_error"] <= 1e-3 for n in UNGUARDED)
    # The markdown states each claim with the same verdict.
    for text, ok in claims.items():
        assert f"- {text}: **{'yes' if ok else 'no'}**." in section["markdown"]


def test_the_book_runs_without_a_penalty_also_drop_d_min(section):
    # Sect. 1.4.1 runs Λ = 0 "ignoring the 2nd constraint": d_min = 0 as well.
    no_penalty = [r for r in BOOK_RUNS if r.overrides.get("lambda_weight", None) == 0.0]
    assert sorted(r.name for r in no_penalty) == sorted(UNGUARDED)
    for run in BOOK_RUNS:
        config = tomllib.loads((section["out"] / "runs" / run.name / "config.toml").read_text())
        planner = config["planner"]
        if run.name in UNGUARDED:
            assert run.overrides.get("d_min") == 0.0, run.name
            assert planner["lambda_weight"] == 0.0 and planner["d_min"] == 0.0, run.name
        else:
            assert planner["lambda_weight"] > 0 and planner["d_min"] > 0, run.name


def test_book_run_overrides_need_no_run_to_check():
    # The same property straight from the run list (fast, without the fixture).
    for run in BOOK_RUNS:
        if run.overrides.get("lambda_weight", 1.0) == 0.0:
            assert run.overrides.get("d_min") == 0.0, run.name
    assert {run.scene for run in BOOK_RUNS} == set(SCENES)
    assert set(BOOK_RUN_OF_SCENE.values()) <= {run.name for run in BOOK_RUNS}


def test_every_run_names_a_packaged_scene():
    for scene, file in SCENES.items():
        path = ch1_report.packaged(file)
        assert Path(path).is_file(), scene
        data = tomllib.loads(Path(path).read_text())
        assert data["planner"]["d_min"] > 0 and data["planner"]["lambda_weight"] > 0, scene


def test_full_mode_comparison_averages_each_seed_once():
    # Synthetic metrics: run k of a (scene, method) has rms_error k, so the mean tells how many
    # runs (and which) entered each row.
    keys = ("rms_error", "max_error", "min_clearance", "min_clearance_settled", "collisions",
            "collisions_settled", "joint_limit_violations", "time_per_iteration_us",
            "time_per_period_us")  # fmt: skip
    runs = [*BOOK_RUNS, *comparison_runs(full=True)]
    metrics = {}
    for run in runs:
        seed = run.overrides.get("seed", 0)
        metrics[run.name] = {k: float(seed) for k in keys}
    table = ch1_report._comparison(metrics)
    for scene in SCENES:
        for method in ("baornn", "baornn-improved"):
            row = table[scene][method]
            assert row["runs"] == len(ch1_report.FULL_SEEDS)
            assert row["rms_error"] == pytest.approx(sum(ch1_report.FULL_SEEDS) / 5)
        for method in ("pinv", "dls", "qp"):
            assert table[scene][method]["runs"] == 1
