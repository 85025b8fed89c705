"""Continuous joints under the twin: a Kinova Jaco 2 started at kinova-ros's home, whose
continuous joints 1 and 4 read 4.80 and 4.20 rad, tracks as it does started at the same pose
written wrapped (−1.48, −2.08 rad): the plan, the stream and the twin all start from the
wrapped pose, and the twin never turns a continuous joint further than the plan does."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.experiments.plan import PlanConfig, run_plan
from articula.runs.folders import SERVO
from articula.scene.config import build_scene
from articula.validation import parse_model
from tests.arms import JACO2_HOME, arm_scene

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"')

CONTINUOUS = [0, 3, 5]  # the Jaco 2's joints 1, 4 and 6
WRAPPED_HOME = [x - 2 * np.pi if j in (0, 3) else x for j, x in enumerate(JACO2_HOME)]


def _jaco_under_the_twin(q0: list[float], method: str):
    """run_plan of the Jaco 2 scene (6 s) from q0 under the twin at 1 kHz: (result, robot)."""
    data = arm_scene("jaco2", duration=6.0)
    data["robot"]["q0"] = q0
    data["planner"] |= {"method": method, "settle": 2.0}
    data |= {"servo": {"rate": 1000}, "plant": {"type": "mujoco"}}
    config = parse_model(PlanConfig, data, "jaco2")
    return run_plan(config), build_scene(config, Path("."))[0].robot


def _joints(trace: dict, name: str) -> np.ndarray:
    """The trace's columns name_1..name_6 as one (k, 6) array."""
    return np.column_stack([trace[f"{name}_{j + 1}"] for j in range(6)])


@pytest.mark.slow
@pytest.mark.parametrize("method", ["qp", "baornn-improved"])
def test_a_jaco_at_its_unwrapped_home_tracks_as_from_the_wrapped_pose(method):
    assert np.max(np.abs(np.array(WRAPPED_HOME))) < np.pi  # the same pose, written wrapped
    (as_read, robot), (wrapped, _) = (_jaco_under_the_twin(q0, method) for q0 in
                                      (JACO2_HOME, WRAPPED_HOME))  # fmt: skip
    assert robot.continuous.tolist() == [j in CONTINUOUS for j in range(6)]
    a, b = as_read.metrics, wrapped.metrics
    for key in ("rms_error", "max_error", "plant_rms_error"):
        assert a[key] == pytest.approx(b[key], abs=5e-5), key  # [m]
    assert a["plant_rms_error"] < 0.002 and a["tracked"]
    # The stream and the twin start where the plan does: at the wrapped home.
    stream = as_read.tables[SERVO]
    np.testing.assert_allclose([stream[f"q_{j + 1}"][0] for j in range(6)], WRAPPED_HOME)
    q, qm = _joints(as_read.trace, "q"), _joints(as_read.trace, "qm")
    assert np.all(np.abs(qm[:, CONTINUOUS]) <= np.pi)  # measured values come back wrapped
    # The twin follows the commands the short way; it turns no continuous joint further.
    lag = robot.difference(qm, q)[:, CONTINUOUS]
    assert np.max(np.abs(lag)) < 0.02  # [rad]
    start = np.array(WRAPPED_HOME)
    commanded = np.abs(robot.difference(np.vstack([start, q])[1:], np.vstack([start, q])[:-1]))
    measured = np.abs(robot.difference(np.vstack([start, qm])[1:], np.vstack([start, qm])[:-1]))
    turned, planned = measured.sum(axis=0)[CONTINUOUS], commanded.sum(axis=0)[CONTINUOUS]
    assert np.all(turned <= planned + 0.02), (turned, planned)  # [rad]
