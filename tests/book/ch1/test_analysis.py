"""Chapter 1's analysis: the comparison table and each claim's rule, on made-up metrics."""

from __future__ import annotations

import pytest

from articula.book.ch1 import analysis
from articula.book.ch1.analysis import AVERAGED, claims, colliding_methods, comparison
from articula.book.ch1.book_values import (
    BOOK_RUN_OF_SCENE,
    BOOK_RUNS,
    FULL_SEEDS,
    GUARDED,
    METHODS,
    SCENES,
    UNGUARDED,
)
from articula.book.ch1.study import comparison_runs


def _metrics(value=lambda run: 0.0) -> dict[str, dict[str, float]]:
    """Every run of the full study with every averaged metric set to value(run)."""
    runs = [*BOOK_RUNS, *comparison_runs(full=True)]
    return {r.name: {k: float(value(r)) for k in AVERAGED} for r in runs}


def _book(**changes: dict[str, float]) -> dict[str, dict[str, float]]:
    """Made-up metrics where every claim holds, with some runs' metrics changed."""
    base = {"rms_error": 5e-4, "min_clearance": 0.06, "min_clearance_settled": 0.07,
            "collisions": 0.0}  # fmt: skip
    m = {r.name: dict(base) for r in BOOK_RUNS}
    for name in UNGUARDED:
        m[name].update(collisions=10.0, min_clearance=-0.01)
    m["fig1_5"].update(min_clearance=0.05, rms_error=9e-4)
    m["fig1_6"].update(min_clearance=0.01, rms_error=8e-4)
    m["fig1_8"].update(min_clearance=0.06, rms_error=9e-4)
    m["fig1_9"].update(min_clearance=0.02, rms_error=8e-4)
    for name, values in changes.items():
        m[name].update(values)
    return m


def _table(improved_rms: float = 1e-4) -> dict:
    row = {"rms_error": 1e-3, "min_clearance": 0.05}
    better = {"rms_error": improved_rms, "min_clearance": 0.06}
    return {s: {"baornn": row, "baornn-equal-evaluations": row, "baornn-improved": better}
            for s in SCENES}  # fmt: skip


def _verdicts(m, table) -> dict[str, str]:
    return {c.name: c.verdict for c in claims(m, table)}


def test_full_mode_comparison_averages_each_seed_once():
    # Run k of a (scene, method) has every metric k: the mean tells which runs entered a row.
    table = comparison(_metrics(lambda run: run.overrides.get("seed", 0)))
    for scene in SCENES:
        for method in ("baornn", "baornn-improved"):
            row = table[scene][method]
            assert row["runs"] == len(FULL_SEEDS)
            assert row["rms_error"] == pytest.approx(sum(FULL_SEEDS) / len(FULL_SEEDS))
            assert row["rms_error_range"] == [min(FULL_SEEDS), max(FULL_SEEDS)]
        for method in ("pinv", "dls", "qp"):
            assert table[scene][method]["runs"] == 1


def test_the_faithful_row_of_a_scene_starts_with_its_book_run():
    m = _metrics()
    m[BOOK_RUN_OF_SCENE["circle"]]["rms_error"] = 5.0
    assert comparison(m)["circle"]["baornn"]["rms_error"] == pytest.approx(5.0 / len(FULL_SEEDS))


def test_colliding_methods_lists_rows_with_a_colliding_step():
    table = {"circle": {"pinv": {"collisions": 3.0}, "qp": {"collisions": 0.0}}}
    assert colliding_methods(table) == [("circle", "pinv")]


def test_every_claim_is_reproduced_on_metrics_that_show_it():
    verdicts = _verdicts(_book(), _table())
    assert set(verdicts.values()) == {"reproduced"}, verdicts
    assert len(verdicts) == 8


@pytest.mark.parametrize(
    ("changes", "claim"),
    [
        ({"fig1_11": {"collisions": 0.0}}, "Λ = 0 collides (Figs. 1.4, 1.11)"),
        ({"fig1_9": {"collisions": 1.0}}, "with Λ > 0 and d_min = 0.002 m there is no collision"),
        ({"fig1_6": {"min_clearance": 0.07}},
         "larger Λ keeps more clearance (Fig. 1.5 vs 1.6, 1.8 vs 1.9)"),
        ({"fig1_8": {"rms_error": 1e-4}}, "larger Λ costs tracking accuracy (Sect. 1.4.2)"),
        ({"fig1_12": {"min_clearance": 0.049}},
         "two obstacles: clearance above 0.05 m (Fig. 1.12)"),
        ({"fig1_4_circle": {"rms_error": 1.1e-3}},
         "Λ = 0 tracks within 1 mm RMS after settling (issue target)"),
    ],
    ids=["collides", "no_collision", "clearance", "accuracy", "two_obstacles", "tracking"],
)  # fmt: skip
def test_each_book_claim_is_not_reproduced_when_its_numbers_contradict_it(changes, claim):
    verdicts = _verdicts(_book(**changes), _table())
    assert verdicts.pop(claim) == "not reproduced"
    assert set(verdicts.values()) == {"reproduced"}, verdicts


def test_the_improved_variant_must_win_on_every_scene():
    verdicts = _verdicts(_book(), _table(improved_rms=2e-3))
    assert verdicts["baornn-improved beats baornn on error at equal or better clearance"] == (
        "not reproduced"
    )


def test_the_tracking_target_is_a_named_constant():
    assert analysis.TRACKING_TARGET == 1e-3
    assert set(GUARDED).isdisjoint(UNGUARDED) and len(METHODS) == 6
