"""What `articula plan --servo-rate 1000` would send to an arm's joint servo, with the jerk
limits on, on the packaged chapter-1 scenes and a Franka Panda among obstacles: every method's
set-points keep the speed, acceleration and jerk limits (by differences from rest at q0), the
1 kHz stream keeps them too (by differences of servo.parquet's positions), passes every
set-point within a sixth of a period's change of motion two periods after it was commanded and
ends at rest,
and no link enters an obstacle, comes within d_min of one, or within self_d_min of another."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.experiments.plan import PlanConfig, load_plan, run_plan
from articula.runs.registry import Result
from articula.scene.config import build_scene
from articula.validation import parse_model
from tests.arms import CONFIGS, arm_scene
from tests.planning.test_safe_commands import BOOK, METHODS

JERK = "velocity+acceleration+jerk"


def streamed(data: dict, method: str) -> tuple[Result, PlanConfig]:
    """run_plan with `method`, the jerk limits and a 1 kHz servo stream, its tolerance lifted
    so that every run is measured."""
    planner = {**data["planner"], "method": method, "tolerance": 10.0, "limits": JERK}
    data = {**data, "planner": planner, "servo": {"rate": 1000}}
    data.pop("experiment", None)
    config = parse_model(PlanConfig, data, "scene")
    return run_plan(config), config


def assert_streamed_within_every_limit(result: Result, config: PlanConfig) -> None:
    """The set-points and the stream within the speed, acceleration and jerk limits; the
    stream passing every set-point; the clearances kept."""
    scene, q0 = build_scene(config, Path("."))
    robot, dt, m = scene.robot, config.planner.dt, result.metrics
    limits = (robot.velocity_limit, robot.acceleration_limit, robot.jerk_limit)
    q = np.column_stack([result.trace[f"q_{j + 1}"] for j in range(robot.nq)])
    motion = robot.difference(np.vstack([q0, q]), np.vstack([q0, q0, q])[:-1])
    motion = np.vstack([np.zeros((2, robot.nq)), motion])  # at rest before q0
    for order, limit in enumerate(limits, start=1):
        rate = np.abs(np.diff(motion, order - 1, axis=0)) / dt**order
        assert np.all(rate <= limit * (1 + 1e-6)), order
    servo = result.tables["servo.parquet"]
    streamed_q = np.column_stack([servo[f"q_{j + 1}"] for j in range(robot.nq)])
    h = servo["t"][1] - servo["t"][0]
    assert h == pytest.approx(1e-3)
    for order, limit in enumerate(limits, start=1):
        rate = np.abs(np.diff(streamed_q, order, axis=0)) / h**order
        assert np.all(rate <= limit * (1 + 1e-6)), order
    assert m["servo_max_jerk_ratio"] <= 1 + 1e-6 and m["max_jerk_ratio"] <= 1 + 1e-6
    ends = [servo[f"{c}_{j + 1}"][-1] for c in ("qd", "qdd") for j in range(robot.nq)]
    assert np.max(np.abs(ends)) < 1e-9  # the stream ends at rest
    assert m["servo_max_deviation"] <= np.max(robot.acceleration_limit) * dt**2 / 6 * (1 + 1e-6)
    assert m["servo_lag_s"] == pytest.approx(2 * dt) and m["servo_clipped"] == 0
    assert m["collisions"] == 0 and m["self_collisions"] == 0
    if config.planner.method in ("baornn", "baornn-improved", "qp"):
        assert m["min_clearance"] > config.planner.d_min
        assert m["min_self_clearance"] >= config.robot.self_d_min - 1e-6


@pytest.mark.slow_cases(keep=("qp-circle_two_obstacles",))
@pytest.mark.parametrize("scene", BOOK)
@pytest.mark.parametrize("method", METHODS)
def test_book_scenes_stream_within_every_limit(scene, method):
    result, config = streamed(load_plan(CONFIGS / f"{scene}.toml"), method)
    assert_streamed_within_every_limit(result, config)


@pytest.mark.slow_cases(keep=("qp",))
@pytest.mark.parametrize("method", METHODS)
def test_a_panda_streams_within_every_limit(method):
    result, config = streamed(arm_scene("panda"), method)
    assert_streamed_within_every_limit(result, config)
