"""planning/velocity_ik.py: the pinv and dls resolved-rate baselines track the book circle within
the joint limits, stay bounded near a singularity (dls), and back away from an obstacle in the
null space without moving the end effector."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.planning.velocity_ik import VelocityIk, VelocityIkParams
from tests.planning.helpers import (
    CIRCLE,
    DT,
    FREE,
    Q_BENT,
    ROBOT,
    assert_tracks_the_circle_within_limits,
    ball,
)


@pytest.mark.parametrize("method", ["pinv", "dls"])
def test_baselines_track_the_book_circle_within_speed_and_joint_limits(method):
    assert_tracks_the_circle_within_limits(VelocityIk(FREE, method, DT))


def test_dls_step_is_bounded_near_a_singularity_where_pinv_is_not():
    # Joints 2, 4, 6 almost straight: the arm is nearly stretched, σ_min(J) ≈ 1e-4.
    q = np.array([0.3, 0.0, 0.2, 0.005, 0.1, 0.0, 0.0])
    J = ROBOT.jacobian(q)[:3]
    U, s, _ = np.linalg.svd(J)
    assert s[-1] < 1e-3
    x = ROBOT.ee_position(q)
    target = x + 0.01 * U[:, 2]  # 1 cm along the direction the arm can barely move in
    unlimited = VelocityIkParams(speed_scale=1e9)  # no speed clamp: the raw steps
    steps = {
        m: np.linalg.norm(VelocityIk(FREE, m, DT, unlimited).step(q, target, 0.0) - q)
        for m in ("pinv", "dls")
    }
    p = unlimited
    # ||J#|| = max σ/(σ² + μ²) <= 1/(2μ): the DLS step is at most dt K |e| / (2μ).
    assert steps["dls"] <= DT * p.gain * 0.01 / (2 * p.damping) * (1 + 1e-9)
    assert steps["pinv"] > 100 * steps["dls"]
    # With the URDF speed limits both are clamped.
    for m in ("pinv", "dls"):
        q_next = VelocityIk(FREE, m, DT).step(q, target, 0.0)
        assert np.all(np.abs(q_next - q) <= DT * ROBOT.velocity_limit * (1 + 1e-9))


def test_dls_matches_pinv_away_from_singularities():
    q = np.array([0.3, 0.6, 0.2, -1.2, 0.1, 0.8, 0.0])
    target = ROBOT.ee_position(q) + np.array([0.002, -0.001, 0.003])
    steps = [VelocityIk(FREE, m, DT).step(q, target, 0.0) - q for m in ("pinv", "dls")]
    assert np.linalg.norm(steps[0]) > 1e-4
    assert np.linalg.norm(steps[1] - steps[0]) < 0.02 * np.linalg.norm(steps[0])


def test_pinv_first_step_from_the_stretched_home_pose_is_not_set_by_round_off():
    rng = np.random.default_rng(0)
    q0 = np.zeros(ROBOT.nq)
    first = VelocityIk(FREE, "pinv", DT).step(q0, CIRCLE(0.0), 0.0) - q0
    for _ in range(3):
        q = 1e-12 * rng.standard_normal(ROBOT.nq)
        step = VelocityIk(FREE, "pinv", DT).step(q, CIRCLE(0.0), 0.0) - q
        assert np.allclose(step, first, atol=1e-6)


@pytest.mark.parametrize("method", ["pinv", "dls"])
def test_null_space_repulsion_backs_away_without_moving_the_end_effector(method):
    scene = ball([0.38, 0.25, 0.62], 0.1)  # 0.10 m from the arm: inside the influence
    x0 = ROBOT.ee_position(Q_BENT)
    for eta, moves in ((0.0, False), (VelocityIkParams().repulsion, True)):
        planner = VelocityIk(scene, method, DT, VelocityIkParams(repulsion=eta))
        q, d = Q_BENT.copy(), [scene.min_distance(Q_BENT)]
        for n in range(30):
            q = planner.step(q, x0, n * DT)  # the reference stands still at the end effector
            d.append(scene.min_distance(q))
        assert np.linalg.norm(ROBOT.ee_position(q) - x0) < 1e-5
        if moves:
            assert np.all(np.diff(d) > 0) and d[-1] > d[0] + 1e-3
        else:
            assert np.allclose(q, Q_BENT)


def test_speed_scale_must_be_positive():
    with pytest.raises(ConfigError, match="speed_scale") as exc:
        VelocityIkParams(speed_scale=0.0)
    assert exc.value.field == "VelocityIkParams.speed_scale"


def test_params_take_keyword_arguments_only():
    with pytest.raises(TypeError):
        VelocityIkParams(20.0)  # type: ignore[misc]
