"""planning/clearance.py: clearance rows (distance and gradient per link-obstacle cell within the
influence distance) against finite differences of the scene's distances."""

from __future__ import annotations

import numpy as np
import pytest

from articula.planning.clearance import clearance_rows
from tests.planning.helpers import Q_BENT, ROBOT, ball
from tests.robots.helpers import central_differences


@pytest.mark.parametrize(
    ("center", "radius", "overlapping"),
    [
        ([0.4, 0.3, 0.6], 0.1, 0),  # separated: every cell d > 0.15 m
        ([0.4, 0.0, 0.75], 0.1, 2),  # links 4-5 overlap the ball (down to d = -0.12 m)
        ([0.3, 0.05, 0.85], 0.12, 3),  # links 3-5 overlap it
    ],
    ids=["separated", "penetrating_a", "penetrating_b"],
)
def test_clearance_gradient_matches_finite_differences_of_scene_distances(
    center, radius, overlapping
):
    scene = ball(center, radius)
    influence = 0.3
    dist = scene.distances(Q_BENT)
    rows = clearance_rows(scene, Q_BENT, 0.0, influence)
    cells = np.argwhere(dist < influence)  # row-major, the order clearance_rows uses
    assert len(rows.distance) == len(cells) > 0
    fd = central_differences(lambda q: scene.distances(q), Q_BENT, 1e-5)
    checked = {"separated": 0, "penetrating": 0}
    for (li, oi), d, grad in zip(cells, rows.distance, rows.gradient, strict=True):
        assert d == pytest.approx(dist[li, oi], abs=1e-12)
        if abs(d) < 0.01:
            continue  # too close to contact for a clean central difference
        assert np.allclose(grad, fd[li, oi], atol=1e-6), (li, d, grad, fd[li, oi])
        # The sign: moving along +∇d increases the clearance (the flip when overlapping).
        assert grad @ fd[li, oi] > 0
        checked["penetrating" if d < 0 else "separated"] += 1
    assert checked["penetrating"] == overlapping  # the cases are what they claim to be
    assert checked["separated"] >= 3


def test_clearance_rows_keep_only_the_cells_within_the_influence_distance():
    scene = ball([0.4, 0.3, 0.6], 0.1)
    dist = scene.distances(Q_BENT)
    # Influence between the 3rd- and 4th-smallest distances: exactly three cells qualify.
    ordered = np.sort(dist.ravel())
    influence = 0.5 * (ordered[2] + ordered[3])
    rows = clearance_rows(scene, Q_BENT, 0.0, influence)
    assert len(rows.distance) == 3
    assert np.all(rows.distance < influence)
    assert np.allclose(np.sort(rows.distance), ordered[:3])
    assert rows.gradient.shape == (3, ROBOT.nq)
    none = clearance_rows(scene, Q_BENT, 0.0, 0.5 * ordered[0])
    assert none.distance.shape == (0,) and none.gradient.shape == (0, ROBOT.nq)


def test_self_pair_rows_match_finite_differences_of_self_distances():
    from articula.scene import Scene

    pairs = [("iiwa_link_0", "iiwa_link_5"), ("iiwa_link_1", "iiwa_link_6"),
             ("iiwa_link_2", "iiwa_link_7")]  # fmt: skip
    scene = Scene(ROBOT, [], self_pairs=pairs)
    q = np.array([0.2, 1.6, 0.1, 1.9, 0.3, 1.2, 0.0])  # folded: the wrist near the base
    rows = clearance_rows(scene, q, 0.0, 0.4)
    d = scene.self_distances(q)
    assert rows.self_pair.all() and len(rows.distance) == np.sum(d < 0.4) >= 2
    fd = central_differences(lambda qq: scene.self_distances(qq), q, 1e-6)
    for distance, grad in zip(rows.distance, rows.gradient, strict=True):
        (k,) = np.flatnonzero(d == distance)
        assert np.allclose(grad, fd[k], atol=1e-6), (scene.self_pair_names[k], grad, fd[k])
