"""The packaged chapter-1 scenes planned as `articula plan` plans them (speed limits on): no
method exceeds a joint speed limit, those that keep clearance never collide, pinv and dls are
reported as colliding, and baornn-improved tracks within 0.5 mm RMS after settling."""

from __future__ import annotations

from pathlib import Path

import pytest

from articula.book.ch1.experiment import PlanConfig, load_plan, run_plan
from articula.validation import parse_model

CONFIGS = Path(__file__).resolve().parents[3] / "src/articula/book/ch1/configs"
SCENES = ["circle_one_obstacle", "circle_two_obstacles", "rectangle_one_obstacle"]


def plan(scene: str, method: str) -> dict[str, float]:
    data = load_plan(CONFIGS / f"{scene}.toml")
    data.pop("experiment")
    data["planner"]["method"] = method
    return run_plan(parse_model(PlanConfig, data, scene)).metrics


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("method", ["baornn", "baornn-improved", "qp", "pinv", "dls"])
def test_speed_limited_plans_of_the_packaged_scenes(scene, method):
    m = plan(scene, method)
    assert m["max_speed_ratio"] <= 1.0 + 1e-9
    if method in ("pinv", "dls"):
        assert m["collisions"] > 0  # they guarantee nothing: `plan` exits 4 on these
    else:
        assert m["collisions"] == 0 and m["min_clearance"] > 0.002  # d_min of the scenes
    if method == "baornn-improved":
        assert m["rms_error"] <= 0.0005
