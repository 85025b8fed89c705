"""Chapter 3's study: its packaged sweeps at each size (the whole run is in test_reproduce)."""

from __future__ import annotations

import pytest

from articula.book.ch3 import study as ch3_study
from articula.book.study import Study


@pytest.mark.parametrize(("full", "delta", "timing"), [(False, 7, 32), (True, 13, 135)])
def test_sweep_configs_are_the_packaged_files_of_the_size(tmp_path, full, delta, timing):
    s = Study(tmp_path / "ch3", full=full)
    assert len(ch3_study.sweep_configs(s, "delta")) == delta
    assert len(ch3_study.sweep_configs(s, "timing")) == timing
    assert (tmp_path / "ch3" / "delta_sweep.toml").is_file()
    assert (tmp_path / "ch3" / "timing_sweep.toml").is_file()


def test_sweeps_hold_the_configs_the_report_describes(tmp_path):
    configs = ch3_study.sweep_configs(Study(tmp_path), "timing")
    assert {c["damping"]["delta"] for c in configs} == {0.3}
    assert all(c["sensor"]["ideal"] for c in configs)
    delta = ch3_study.sweep_configs(Study(tmp_path), "delta")
    assert delta[0]["damping"]["delta"] == 0.0


def test_search_size_follows_the_study():
    assert ch3_study.ITERATIONS[Study(out=None, full=False).size] == 12
    assert ch3_study.ITERATIONS[Study(out=None, full=True).size] == 40
