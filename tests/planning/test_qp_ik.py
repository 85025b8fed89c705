"""planning/qp_ik.py: the QP baseline tracks the book circle within the joint limits, its dampers
keep clearance to an obstacle in the way, it counts the periods without a solution, and its
parameters refuse a safety distance beyond the influence distance."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.geometry.poses import pose
from articula.geometry.shapes import box
from articula.loops.tracking import track
from articula.planning import qp_ik
from articula.planning.qp_ik import QpIk, QpIkParams
from articula.planning.rate_limits import RateLimits
from articula.scene import Obstacle, Scene
from tests.planning.helpers import (
    CIRCLE,
    DT,
    FREE,
    ROBOT,
    assert_tracks_the_circle_within_limits,
    ball,
)

# On the obstacle-free QP's approach from q = 0 (its end effector passes here at t = 0.5 s).
BLOCKING_BALL = ([0.308, 0.645, 0.693], 0.05)


def test_qp_tracks_the_book_circle_within_speed_and_joint_limits():
    planner = QpIk(FREE, DT)
    assert_tracks_the_circle_within_limits(planner)
    assert planner.infeasible == 0


def test_qp_dampers_keep_clearance_with_an_obstacle_across_the_approach():
    scene = ball(*BLOCKING_BALL)
    q0 = np.zeros(ROBOT.nq)
    blind = track(QpIk(FREE, DT), CIRCLE, q0, DT, 2.0)
    assert scene.min_distance_batch(blind.q).min() < -0.05  # the ball is really in the way
    planner = QpIk(scene, DT)
    r = track(planner, CIRCLE, q0, DT, 4.0)
    assert r.clearance.min() > 0.0
    assert r.clearance.min() > 0.5 * planner.params.safety  # the damper's floor, discretised
    assert planner.infeasible == 0
    assert r.error[r.t >= 3.0].max() < 1e-3  # and it still reaches the circle


def test_qp_counts_the_periods_without_a_solution_and_stays_put(monkeypatch):
    solve = qp_ik.daqp.solve

    def every_third_period_fails(*args, **kwargs):
        x, value, status, info = solve(*args, **kwargs)
        failing = planner.iterations % 3 == 2  # both the solve and its relaxed retry
        return x, value, -1 if failing else status, info  # -1: infeasible

    monkeypatch.setattr(qp_ik.daqp, "solve", every_third_period_fails)
    planner = QpIk(FREE, DT)
    q = np.zeros(ROBOT.nq)
    moved = []
    for n in range(30):
        q_next = planner.step(q, CIRCLE(n * DT), n * DT)
        moved.append(not np.array_equal(q_next, q))
        q = q_next
    assert planner.iterations == 30
    assert planner.infeasible == 10
    assert moved == [(n + 1) % 3 != 0 for n in range(30)]


def test_qp_is_not_frozen_by_a_table_just_under_the_fixed_base():
    # A table top 1 cm below the base plate: nothing the joints do can change that distance.
    table = Obstacle("table", (box((1.0, 1.0, 0.04)),), pose([0.0, 0.0, -0.03]))
    scene = Scene(ROBOT, [table])
    assert 0 < scene.min_distance(np.zeros(ROBOT.nq)) < QpIkParams().safety
    planner = QpIk(scene, DT)
    r = track(planner, CIRCLE, np.zeros(ROBOT.nq), DT, 3.0)
    assert planner.infeasible == 0
    assert r.error[-1] < 1e-2


def test_qp_params_refuse_a_safety_distance_beyond_the_influence():
    with pytest.raises(ConfigError, match="safety") as exc:
        QpIkParams(influence=0.1, safety=0.1)
    assert exc.value.field == "QpIkParams.safety"
    with pytest.raises(ConfigError, match="safety") as exc:
        QpIkParams(limit_influence=0.1, limit_safety=0.2)
    assert exc.value.field == "QpIkParams.limit_safety"


def test_speed_scale_must_be_positive():
    with pytest.raises(ConfigError, match="speed_scale") as exc:
        QpIkParams(speed_scale=0.0)
    assert exc.value.field == "QpIkParams.speed_scale"


@pytest.mark.parametrize("start_clearance", [0.015, 0.005])
def test_qp_starts_from_inside_its_dampers_safety_distance(start_clearance):
    # A ball 15 mm (or 5 mm) from the arm at rest: inside the 30 mm safety distance, outside
    # d_min. Under jerk limits no first period can push every damper's row out as fast as it
    # asks; the dampers then ask only that the arm not approach, and it sets off.
    q0 = np.zeros(ROBOT.nq)
    centre = np.array([0.2, 0.0, 0.6])
    for _ in range(5):  # move the ball along x until the start's clearance is as asked
        centre[0] += start_clearance - ball(centre, 0.05).clearances(q0)[0]
    scene = ball(centre, 0.05)
    assert scene.clearances(q0)[0] == pytest.approx(start_clearance, abs=1e-6)
    assert start_clearance < QpIkParams().safety
    rate = RateLimits(ROBOT.velocity_limit, DT, ROBOT.acceleration_limit, ROBOT.jerk_limit)
    planner = QpIk(scene, DT, d_min=0.002, rate=rate)
    r = track(planner, CIRCLE, q0, DT, 6.0)
    assert r.error[-1] < 1e-3  # it left the start and reached the circle
    assert r.clearance.min() > 0.002
    assert planner.infeasible < 0.1 * len(r.t)
