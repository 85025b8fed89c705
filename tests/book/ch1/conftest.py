"""The chapter-1 study run once, in quick mode with every run cut short, for the tests here."""

from __future__ import annotations

from typing import Any

import pytest

from articula.book import ch1
from articula.book.ch1 import study
from articula.book.study import Study

SHORT = {"duration": 1.5, "settle": 1.0}  # [s] of simulated time per run


@pytest.fixture(scope="package")
def section(tmp_path_factory) -> dict[str, Any]:
    """ch1.reproduce in quick mode, one worker, every run cut to 1.5 s (settle 1 s)."""
    report = tmp_path_factory.mktemp("report")
    out = report / "ch1"  # reproduce() passes OUT/ch1; the markdown links are relative to OUT
    original = study.plan_config
    configs: dict[str, dict[str, Any]] = {}

    def short(run):
        config = original(run)
        config["planner"] = {**config["planner"], **SHORT}
        configs[run.name] = config
        return config

    ticks: list[tuple[int, int]] = []
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(study, "plan_config", short)
        result = ch1.reproduce(Study(out, progress=lambda done, total: ticks.append((done, total))))
    return {"report": report, "out": out, "section": result, "configs": configs, "ticks": ticks}
