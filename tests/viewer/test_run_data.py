"""viewer/run_data.py: a run folder read back for display agrees with the scene it names."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from articula.viewer.run_data import RunFolderError, load_run, run_folders


def test_the_closest_pair_is_the_scenes_minimum_and_the_links_are_drawn(planned_run):
    run = load_run(planned_run)
    n = len(run.t)
    assert len(run.q) == n > 300 and run.q.shape[1] == run.scene.robot.nq  # approach + 3 s
    assert set(run.visuals) >= {"iiwa_link_1", "iiwa_link_7"}
    for k in (0, n // 2, n - 1):
        closest = run.closest(k)
        d = run.scene.clearances(run.q[k], float(run.t[k]))[0]  # link-obstacle
        assert closest.distance == pytest.approx(d, abs=1e-9)
        assert np.linalg.norm(closest.on_link - closest.on_obstacle) == pytest.approx(d, abs=1e-6)
        assert min(run.link_clearances(k).values()) == pytest.approx(d, abs=1e-9)
        assert closest.distance == pytest.approx(run.clearance[k], abs=1e-9)  # the trace's


def test_a_sweep_folder_lists_its_planner_runs(planned_run, tmp_path):
    for name in ("b0", "a1"):
        shutil.copytree(planned_run, tmp_path / name)
    (tmp_path / "notes").mkdir()
    assert [p.name for p in run_folders(tmp_path)] == ["a1", "b0"]
    assert run_folders(planned_run) == [planned_run]
    with pytest.raises(RunFolderError, match="no planner run"):
        run_folders(tmp_path / "notes")
