"""Self-collision: the allowed-collision matrix (scene/self_collision.py) and the Scene's link-link
distances, against a brute-force hull-distance QP on random configurations."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import qpsolvers

from articula.errors import ConfigError
from articula.robots import RobotModel
from articula.scene import Scene
from articula.scene.self_collision import self_collision_matrix

ROBOT = RobotModel.builtin("iiwa14")
LINKS = [link.name for link in ROBOT.links]


def hull_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Distance [m] between the convex hulls of point sets a and b (0 when they overlap):
    min |Aᵀλ − Bᵀμ|² over the two simplices, a QP independent of GJK."""
    na, nb = len(a), len(b)
    M = np.hstack([a.T, -b.T])  # 3 × (na + nb)
    P = M.T @ M + 1e-12 * np.eye(na + nb)
    A = np.zeros((2, na + nb))
    A[0, :na] = 1.0
    A[1, na:] = 1.0
    x = qpsolvers.solve_qp(P, np.zeros(na + nb), A=A, b=np.ones(2),
                           lb=np.zeros(na + nb), ub=np.ones(na + nb), solver="daqp")  # fmt: skip
    gap = M @ x
    return float(np.sqrt(max(gap @ gap, 0.0)))


def link_points(q: np.ndarray, name: str) -> list[np.ndarray]:
    """World vertices of each collision shape of link `name` at q."""
    poses = ROBOT.link_poses(q)
    link = ROBOT.links[LINKS.index(name)]
    out = []
    for shape, T in zip(link.shapes, link.placements, strict=True):
        W = poses[name] @ T
        out.append(shape.vertices @ W[:3, :3].T + W[:3, 3])
    return out


@pytest.mark.slow
def test_self_distances_match_a_brute_force_hull_distance_on_random_configurations():
    pairs = [(a, b) for i, a in enumerate(LINKS) for b in LINKS[i + 2 :]]  # not adjacent
    scene = Scene(ROBOT, [], self_pairs=pairs)
    rng = np.random.default_rng(2)
    seen = {"apart": 0, "overlap": 0}
    folded = [0.0, 1.9, 0.0, 2.0, 0.0, 2.0, 0.0]  # the flange folded onto link 5
    for q in [folded, *rng.uniform(ROBOT.lower, ROBOT.upper, (12, ROBOT.nq))]:
        q = np.asarray(q)
        d = scene.self_distances(q)
        for (a, b), d_pair in zip(scene.self_pair_names, d, strict=True):
            oracle = min(hull_distance(pa, pb) for pa in link_points(q, a)
                         for pb in link_points(q, b))  # fmt: skip
            if d_pair > 1e-6:
                assert d_pair == pytest.approx(oracle, abs=1e-5), (a, b)  # the QP stops at ~µm
                seen["apart"] += 1
            else:
                assert oracle < 1e-4, (a, b)  # GJK/EPA says they overlap: the QP agrees
                seen["overlap"] += 1
        assert scene.self_clearance(q) == pytest.approx(d.min(), abs=0)
        assert scene.min_distance(q) == pytest.approx(d.min(), abs=1e-12)
    assert seen["apart"] > 100 and seen["overlap"] > 0


def test_matrix_skips_adjacent_links_and_pairs_that_never_come_close():
    matrix = self_collision_matrix(ROBOT)
    for a, b in itertools.pairwise(LINKS):
        assert matrix.skipped[a, b] == "adjacent"
    # Over 1000 samples the shoulder links never come within 2 cm of link 3: skipped.
    assert matrix.skipped["iiwa_link_1", "iiwa_link_3"] == "never close"
    # The base can be hit by the wrist and the flange; the flange can fold onto link 5.
    assert ("iiwa_link_0", "iiwa_link_5") in matrix.checked
    assert ("iiwa_link_5", "iiwa_link_7") in matrix.checked
    every = {(a, b) for i, a in enumerate(LINKS) for b in LINKS[i + 1 :]}
    assert set(matrix.checked) | set(matrix.skipped) == every
    assert not set(matrix.checked) & set(matrix.skipped)


def test_matrix_reasons_follow_the_sampled_distances():
    matrix = self_collision_matrix(ROBOT, samples=300, margin=0.05, seed=4)
    candidates = [p for p in matrix.checked] + [
        p for p, why in matrix.skipped.items() if why in ("never close", "always touching")
    ]
    scene = Scene(ROBOT, [], self_pairs=candidates)
    rng = np.random.default_rng(4)
    D = np.array([scene.self_distances(q)
                  for q in rng.uniform(ROBOT.lower, ROBOT.upper, (300, ROBOT.nq))])  # fmt: skip
    for pair, column in zip(scene.self_pair_names, D.T, strict=True):
        why = matrix.skipped.get(pair)
        if why == "never close":
            assert column.min() > 0.05
        elif why == "always touching":
            assert column.max() <= 0.0
        else:
            assert column.min() <= 0.05 and column.max() > 0.0


def test_allowed_pairs_are_not_checked_and_bad_names_are_refused():
    matrix = self_collision_matrix(ROBOT, allow_pairs=[["iiwa_link_7", "iiwa_link_5"]])
    assert matrix.skipped["iiwa_link_5", "iiwa_link_7"] == "allowed"
    assert ("iiwa_link_5", "iiwa_link_7") not in matrix.checked
    with pytest.raises(ConfigError, match=r"allow_pairs.*no link 'gripper'"):
        self_collision_matrix(ROBOT, allow_pairs=[["gripper", "iiwa_link_5"]])
    with pytest.raises(ConfigError, match="itself"):
        self_collision_matrix(ROBOT, allow_pairs=[["iiwa_link_5", "iiwa_link_5"]])
    with pytest.raises(ConfigError, match=r"self_pairs.*no link 'x'"):
        Scene(ROBOT, [], self_pairs=[("x", "iiwa_link_1")])


def test_the_same_matrix_for_the_same_seed():
    first = self_collision_matrix(ROBOT, samples=200, seed=9)
    assert first == self_collision_matrix(ROBOT, samples=200, seed=9)


def chain_robot(tmp_path, links: int) -> RobotModel:
    """A chain of `links` boxes, 0.1 m apart on revolute joints about x and y in turn (±2.6 rad),
    so that links some way apart can fold onto each other."""
    body = "".join(
        f'<link name="l{i}"><collision><origin xyz="0 0 0.05"/><geometry>'
        '<box size="0.03 0.03 0.09"/></geometry></collision></link>'
        for i in range(links)
    )
    body += "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0 0 0.1"/><axis xyz="{"0 1 0" if i % 2 else "1 0 0"}"/>'
        '<limit lower="-2.6" upper="2.6" effort="1" velocity="1"/></joint>'
        for i in range(links - 1)
    )
    path = tmp_path / "chain.urdf"
    path.write_text(f'<robot name="chain">{body}</robot>')
    return RobotModel.from_urdf(path, max_links=links)


def test_the_sphere_bounds_decide_as_the_exact_distances_on_every_sample(tmp_path):
    """On a 24-link chain the matrix equals the one brute force gives: every candidate pair's
    exact distance at every sample (the bounds only spare the queries they rule out)."""
    robot = chain_robot(tmp_path, 24)
    matrix = self_collision_matrix(robot, samples=150, margin=0.02, seed=2)
    names = [link.name for link in robot.links]
    candidates = [pair for pair in itertools.combinations(names, 2)
                  if matrix.skipped.get(pair) != "adjacent"]  # fmt: skip
    scene = Scene(robot, [], self_pairs=candidates)
    Q = np.random.default_rng(2).uniform(*robot.sample_range, (150, robot.nq))
    D = np.array([scene.self_distances(q) for q in Q])
    for pair, column in zip(scene.self_pair_names, D.T, strict=True):
        expected = ("never close" if column.min() > 0.02
                    else "always touching" if column.max() <= 0.0 else None)  # fmt: skip
        assert matrix.skipped.get(pair) == expected, pair
    assert matrix.checked  # the chain does fold onto itself


def test_the_matrix_is_kept_on_disk_and_read_back(tmp_path, monkeypatch):
    monkeypatch.setenv("ARTICULA_CACHE_DIR", str(tmp_path / "cache"))
    first = self_collision_matrix(ROBOT, samples=100, seed=1)
    (kept,) = (tmp_path / "cache").glob("self_collision-*.json")

    def not_again(*args, **kwargs):
        raise AssertionError("computed again instead of read from the cache")

    monkeypatch.setattr("articula.scene.self_collision._decide", not_again)
    assert self_collision_matrix(ROBOT, samples=100, seed=1) == first
    with pytest.raises(AssertionError, match="computed again"):  # other settings: another key
        self_collision_matrix(ROBOT, samples=101, seed=1)
    kept.write_text("{not json")  # a damaged file is computed again, not trusted
    monkeypatch.undo()
    monkeypatch.setenv("ARTICULA_CACHE_DIR", str(tmp_path / "cache"))
    assert self_collision_matrix(ROBOT, samples=100, seed=1) == first


def test_pairs_left_undecided_by_the_query_budget_are_checked(tmp_path, monkeypatch):
    robot = chain_robot(tmp_path, 16)
    full = self_collision_matrix(robot, samples=100, seed=3)
    monkeypatch.setenv("ARTICULA_CACHE_DIR", str(tmp_path / "other"))
    monkeypatch.setattr("articula.scene.self_collision.MAX_QUERIES", 50)
    bounded = self_collision_matrix(robot, samples=100, seed=3)
    assert set(full.checked) < set(bounded.checked)  # the safe side: more pairs checked
    assert {p for p, why in bounded.skipped.items() if why == "never close"} <= {
        p for p, why in full.skipped.items() if why == "never close"
    }
