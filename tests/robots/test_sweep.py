"""robots/sweep.py: the bound on how far a joint motion moves any point of the arm, against the
links' vertices moved by random motions (the oracle)."""

from __future__ import annotations

import numpy as np
import pytest

from articula.robots import RobotModel
from articula.robots.sweep import joint_sweep

IIWA = RobotModel.builtin("iiwa14")


def _vertices(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    """Every collision vertex of the arm at q, in the world [m]."""
    poses = robot.link_poses(q)
    out = []
    for link in robot.links:
        for shape, placement in zip(link.shapes, link.placements, strict=True):
            T = poses[link.name] @ placement
            out.append(shape.vertices @ T[:3, :3].T + T[:3, 3])
    return np.vstack(out)


@pytest.mark.parametrize("size", [0.01, 0.1, 0.5])
def test_no_vertex_moves_farther_than_the_bound(size):
    sweep = joint_sweep(IIWA)
    assert sweep.shape == (7,) and np.all(np.diff(sweep) <= 1e-12)  # farther joints move less
    rng = np.random.default_rng(5)
    for _ in range(200):
        q = rng.uniform(IIWA.lower, IIWA.upper)
        dq = rng.uniform(-size, size, 7)
        moved = np.linalg.norm(_vertices(IIWA, q + dq) - _vertices(IIWA, q), axis=1).max()
        assert moved <= sweep @ np.abs(dq) + 1e-12


def test_the_base_joints_bound_is_the_arms_reach():
    # Joint 1 turns everything beyond it: its bound is at least the farthest vertex from it.
    sweep = joint_sweep(IIWA)
    axis_origin = IIWA.link_poses(np.zeros(7))["iiwa_link_1"][:3, 3]
    farthest = np.linalg.norm(_vertices(IIWA, np.zeros(7)) - axis_origin, axis=1).max()
    assert sweep[0] >= farthest
