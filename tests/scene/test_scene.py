"""scene/scene.py: distances against independent oracles: a small QP and the Minkowski difference
for random polytopes, closed forms for primitives, brute force for the vertex metric; broad phase
identity; the scene's refusals."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.optimize import minimize
from scipy.spatial import ConvexHull
from scipy.spatial.distance import cdist
from scipy.spatial.transform import Rotation

from articula.errors import ConfigError
from articula.geometry.shapes import box, capsule, convex_hull, cylinder, sphere
from articula.robots.model import RobotModel
from articula.scene import Obstacle, Scene
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml
from tests.scene.helpers import (
    CONFIGS,
    box_signed_distance,
    one_link_robot,
    pair_scene,
    rigid,
    signed,
    world,
)

TWO_OBSTACLES = CONFIGS / "two_obstacles.toml"

# ----- the polytope oracle ----------------------------------------------------------------------


def hull_excess(points: np.ndarray, hull_points: np.ndarray) -> np.ndarray:
    """Signed distance of each point beyond the farthest face plane of hull(hull_points)."""
    eq = ConvexHull(hull_points).equations
    return (np.atleast_2d(points) @ eq[:, :3].T + eq[:, 3]).max(axis=1)


def _origin_to_segments(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Distance from the origin to each segment p[i]-q[i]."""
    e = q - p
    t = np.clip(-np.einsum("ij,ij->i", p, e) / np.einsum("ij,ij->i", e, e), 0.0, 1.0)
    return np.linalg.norm(p + t[:, None] * e, axis=1)


def _origin_to_triangles(tri: np.ndarray) -> np.ndarray:
    """Distance from the origin to each triangle tri[i] (3 corners): the plane distance when the
    origin projects inside the triangle, else the nearest edge."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    height = np.einsum("ij,ij->i", a, n)
    foot = height[:, None] * n  # the origin projected on the plane
    inside = np.ones(len(tri), bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, foot - u), n) >= 0
    edges = np.minimum.reduce(
        [_origin_to_segments(a, b), _origin_to_segments(b, c), _origin_to_segments(c, a)]
    )
    return np.where(inside, np.abs(height), edges)


def polytope_signed_distance(A: np.ndarray, B: np.ndarray) -> float:
    """Signed distance between hull(A) and hull(B), from their Minkowski difference D = A ⊖ B:
    apart, the distance from the origin to D (reached on one of D's boundary triangles);
    overlapping, minus the penetration depth (the distance to D's nearest face plane)."""
    diff = (A[:, None, :] - B[None, :, :]).reshape(-1, 3)
    hull = ConvexHull(diff)
    offsets = hull.equations[:, 3]  # plane offsets at the origin: all < 0 iff it is inside
    if offsets.max() < 0:
        return float(offsets.max())
    return float(_origin_to_triangles(diff[hull.simplices]).min())


def _box_corners(centre, half) -> np.ndarray:
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    return np.asarray(centre) + signs * half


def test_the_oracle_on_boxes():
    # The oracle itself, on axis-aligned boxes: apart, the norm of the per-axis gaps;
    # overlapping, the smallest per-axis overlap.
    rng = np.random.default_rng(11)
    for _ in range(40):
        h1, h2 = rng.uniform(0.05, 0.3, 3), rng.uniform(0.05, 0.3, 3)
        c1, c2 = rng.uniform(-0.4, 0.4, 3), rng.uniform(-0.4, 0.4, 3)
        overlap = h1 + h2 - np.abs(c1 - c2)
        expected = (
            -overlap.min() if np.all(overlap > 0) else np.linalg.norm(np.maximum(-overlap, 0))
        )
        got = polytope_signed_distance(_box_corners(c1, h1), _box_corners(c2, h2))
        assert got == pytest.approx(expected, abs=1e-12)


# ----- hypothesis strategies --------------------------------------------------------------------

TETRA = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
unit = st.floats(-1.0, 1.0, allow_nan=False, allow_subnormal=False)


@st.composite
def clouds(draw) -> np.ndarray:
    """4-14 points: a scaled, squashed tetrahedron (never flat) plus extra points around it."""
    size = draw(st.floats(0.02, 0.3))
    squash = draw(arrays(np.float64, 3, elements=st.floats(0.3, 1.0)))
    extra = draw(arrays(np.float64, (draw(st.integers(0, 10)), 3), elements=unit))
    return size * np.vstack([TETRA, extra]) * squash


@st.composite
def poses(draw, reach: float = 0.4, offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    rotvec = draw(arrays(np.float64, 3, elements=st.floats(-math.pi, math.pi)))
    p = draw(arrays(np.float64, 3, elements=st.floats(-reach, reach)))
    return rigid(Rotation.from_rotvec(rotvec).as_matrix(), p + np.asarray(offset))


# Hypothesis favours round numbers; with equal clouds, a relative shift of exactly (±1e-6)³ hits
# the coal GJK defect pinned down by test_coal_gjk_micron_shift_of_identical_tetrahedra. Offsetting
# the obstacle by an irrational amount keeps that one measure-zero case out of the random tests.
SKEW = 1e-3 * np.array([1 / 3, 1 / 7, 1 / 11])


# coal stops GJK within its tolerance (1e-6, relative to distances below 1 m here): answers may
# exceed the exact distance by that much, and depend on which shape comes first by as much.
GJK_TOL = 2e-6
POLY = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ----- random polytopes -------------------------------------------------------------------------


@POLY
@given(A=clouds(), B=clouds(), Ta=poses(0.25), Tb=poses(0.25, SKEW))
def test_polytope_signed_distance_matches_oracle(A, B, Ta, Tb):
    d = signed(convex_hull(A), Ta, convex_hull(B), Tb)
    expected = polytope_signed_distance(world(Ta, A), world(Tb, B))
    event("overlapping" if expected < 0 else "separated")
    assert d == pytest.approx(expected, abs=GJK_TOL)


@POLY
@given(A=clouds(), B=clouds(), Ta=poses(), Tb=poses(offset=SKEW))
def test_polytope_distance_is_symmetric(A, B, Ta, Tb):
    a, b = convex_hull(A), convex_hull(B)
    assert signed(a, Ta, b, Tb) == pytest.approx(signed(b, Tb, a, Ta), abs=GJK_TOL)


@POLY
@given(A=clouds(), B=clouds(), Ta=poses(), Tb=poses(offset=SKEW), G=poses(reach=2.0))
def test_polytope_distance_is_invariant_under_rigid_motion(A, B, Ta, Tb, G):
    a, b = convex_hull(A), convex_hull(B)
    assert signed(a, G @ Ta, b, G @ Tb) == pytest.approx(signed(a, Ta, b, Tb), abs=GJK_TOL)


@POLY
@given(A=clouds(), B=clouds(), Ta=poses(), Tb=poses(offset=SKEW))
def test_polytope_witnesses(A, B, Ta, Tb):
    a, b = convex_hull(A), convex_hull(B)
    w = pair_scene(a, Ta, b, Tb).witnesses([0.0])
    d, p_link, p_obstacle = w.distance[0, 0], w.on_link[0, 0], w.on_obstacle[0, 0]
    assert d == signed(a, Ta, b, Tb)
    # Each witness lies on (or in) its own shape.
    assert hull_excess(p_link, world(Ta, A))[0] < 1e-7
    assert hull_excess(p_obstacle, world(Tb, B))[0] < 1e-7
    gap = float(np.linalg.norm(p_obstacle - p_link))
    if d > 0:
        assert gap == pytest.approx(d, abs=1e-7)
    else:
        # Overlapping: the witnesses span the penetration; sliding the link shape by their
        # difference (the minimal translation) leaves the two shapes just touching.
        assert gap == pytest.approx(-d, abs=GJK_TOL)
        shifted = Ta.copy()
        shifted[:3, 3] += p_obstacle - p_link
        assert abs(signed(a, shifted, b, Tb)) < 1e-5


def test_overlap_of_boxes_is_the_smallest_axis_overlap():
    # Axis-aligned boxes: the minimal separating translation is along the axis of least overlap.
    rng = np.random.default_rng(7)
    for _ in range(30):
        h1, h2 = rng.uniform(0.05, 0.3, 3), rng.uniform(0.05, 0.3, 3)
        c1, c2 = rng.uniform(-0.1, 0.1, 3), rng.uniform(-0.1, 0.1, 3)
        overlap = h1 + h2 - np.abs(c1 - c2)
        d = signed(box(2 * h1), rigid(np.eye(3), c1), box(2 * h2), rigid(np.eye(3), c2))
        if np.all(overlap > 0):
            assert d == pytest.approx(-overlap.min(), abs=1e-7)
        else:
            assert d == pytest.approx(np.linalg.norm(np.maximum(-overlap, 0)), abs=1e-7)


@pytest.mark.xfail(
    strict=True,
    reason="coal 3.0.3 GJK: two identical tetrahedra 0.35 m across, one shifted by exactly "
    "(1e-6, 1e-6, 1e-6) m (or any sign pattern of it), are reported 1e-6 m apart although they "
    "overlap by 0.25 m; plain coal.distance gives the same, a 2e-6 or 0.9e-6 shift does not",
)
def test_coal_gjk_micron_shift_of_identical_tetrahedra():
    a = convex_hull(0.125 * TETRA)
    d = signed(a, np.eye(4), a, rigid(np.eye(3), [1e-6, 1e-6, 1e-6]))
    expected = polytope_signed_distance(0.125 * TETRA, 0.125 * TETRA + 1e-6)
    assert expected == pytest.approx(-0.249999, abs=1e-9)
    assert d == pytest.approx(expected, abs=1e-6)


def _qp_distance(A: np.ndarray, B: np.ndarray) -> float:
    """min ‖Aᵀλ − Bᵀμ‖ over the simplices λ, μ by SLSQP: a feasible point, so never below the
    true distance."""
    n, m = len(A), len(B)

    def objective(x):
        d = A.T @ x[:n] - B.T @ x[n:]
        return d @ d, np.concatenate([2 * A @ d, -2 * B @ d])

    ones_a, ones_b = np.r_[np.ones(n), np.zeros(m)], np.r_[np.zeros(n), np.ones(m)]
    res = minimize(
        objective,
        np.r_[np.full(n, 1 / n), np.full(m, 1 / m)],
        jac=True,
        method="SLSQP",
        bounds=[(0.0, 1.0)] * (n + m),
        constraints=[
            {"type": "eq", "fun": lambda x: x @ ones_a - 1, "jac": lambda x: ones_a},
            {"type": "eq", "fun": lambda x: x @ ones_b - 1, "jac": lambda x: ones_b},
        ],
        options={"ftol": 1e-15, "maxiter": 1000},
    )
    x = np.clip(res.x, 0.0, None)
    lam, mu = x[:n] / x[:n].sum(), x[n:] / x[n:].sum()  # exactly feasible
    return float(np.linalg.norm(A.T @ lam - B.T @ mu))


def test_the_oracle_against_the_qp():
    # The Minkowski-difference oracle against the QP min ‖Aᵀλ − Bᵀμ‖ on separated random clouds.
    rng = np.random.default_rng(12)
    for _ in range(12):
        A = rng.normal(size=(rng.integers(4, 12), 3)) * 0.1
        B = rng.normal(size=(rng.integers(4, 12), 3)) * 0.1 + rng.normal(size=3) * 0.3
        exact = polytope_signed_distance(A, B)
        if exact <= 0:
            continue
        qp = _qp_distance(A, B)
        assert qp >= exact - 1e-12
        assert qp == pytest.approx(exact, abs=1e-6)


# ----- primitives against closed forms ----------------------------------------------------------


def _segment_distance(point: np.ndarray, half_length: float) -> float:
    z = np.clip(point[2], -half_length, half_length)
    return float(np.linalg.norm(point - [0.0, 0.0, z]))


def _cylinder_signed_distance(point: np.ndarray, radius: float, half_length: float) -> float:
    dr = math.hypot(point[0], point[1]) - radius
    dz = abs(point[2]) - half_length
    return math.hypot(max(dr, 0.0), max(dz, 0.0)) + min(max(dr, dz), 0.0)


primitive_cases = st.tuples(
    st.floats(0.02, 0.3), poses(), arrays(np.float64, 3, elements=st.floats(-0.6, 0.6))
)


@settings(max_examples=40, deadline=None)
@given(r1=st.floats(0.01, 0.3), r2=st.floats(0.01, 0.3), case=primitive_cases)
def test_sphere_sphere(r1, r2, case):
    _, T, centre = case
    expected = float(np.linalg.norm(centre - T[:3, 3])) - r1 - r2
    assume(abs(expected + r1 + r2) > 1e-3)  # concentric spheres have no penetration direction
    got = signed(sphere(r1), rigid(np.eye(3), centre), sphere(r2), T)
    assert got == pytest.approx(expected, abs=1e-7)


@settings(max_examples=40, deadline=None)
@given(size=arrays(np.float64, 3, elements=st.floats(0.02, 0.6)), case=primitive_cases)
def test_box_sphere(size, case):
    r, T, centre = case
    local = np.linalg.solve(T[:3, :3], centre - T[:3, 3])
    sd = box_signed_distance(local, size / 2)
    if sd < 0:  # sphere centre inside the box: the nearest face must be unambiguous
        q = np.sort(size / 2 - np.abs(local))
        assume(q[1] - q[0] > 1e-4)
    expected = sd - r
    # Sphere on the link, box as the obstacle, and the other way round.
    got = signed(sphere(r), rigid(np.eye(3), centre), box(size), T)
    assert got == pytest.approx(expected, abs=1e-6)
    assert signed(box(size), T, sphere(r), rigid(np.eye(3), centre)) == pytest.approx(
        expected, abs=1e-6
    )


@settings(max_examples=40, deadline=None)
@given(radius=st.floats(0.01, 0.2), length=st.floats(0.01, 0.8), case=primitive_cases)
def test_capsule_sphere(radius, length, case):
    r, T, centre = case
    local = np.linalg.solve(T[:3, :3], centre - T[:3, 3])
    gap = _segment_distance(local, length / 2)
    assume(gap > 1e-4)  # a centre on the core segment has no unique penetration direction
    got = signed(sphere(r), rigid(np.eye(3), centre), capsule(radius, length), T)
    assert got == pytest.approx(gap - radius - r, abs=1e-6)


@settings(max_examples=40, deadline=None)
@given(radius=st.floats(0.02, 0.3), length=st.floats(0.02, 0.8), case=primitive_cases)
def test_cylinder_sphere_with_the_centre_outside(radius, length, case):
    r, T, centre = case
    local = np.linalg.solve(T[:3, :3], centre - T[:3, 3])
    sd = _cylinder_signed_distance(local, radius, length / 2)
    assume(sd > 1e-4)  # overlapping or not, as long as the sphere's centre is outside
    got = signed(sphere(r), rigid(np.eye(3), centre), cylinder(radius, length), T)
    assert got == pytest.approx(sd - r, abs=1e-6)


@pytest.mark.xfail(
    strict=True,
    reason="coal 3.0.3's sphere-cylinder distance ignores the caps when the sphere's centre is "
    "inside the cylinder: it reports the radial escape (-0.6 m here) instead of the true "
    "penetration through the nearer cap (-0.15 m), so Scene over-states the penetration",
)
@pytest.mark.parametrize("centre", [(0.0, 0.0, 0.45), (0.2, -0.1, -0.42)])
def test_sphere_deep_in_a_cylinder_escapes_through_the_nearest_cap(centre):
    # Cylinder r = 0.5, length 1 (caps at z = ±0.5), sphere r = 0.1 with its centre inside.
    local = np.array(centre)
    expected = _cylinder_signed_distance(local, 0.5, 0.5) - 0.1  # -(0.1 + 0.05) on the axis
    assert expected > -0.2
    got = signed(sphere(0.1), rigid(np.eye(3), local), cylinder(0.5, 1.0), np.eye(4))
    assert got == pytest.approx(expected, abs=1e-6)


def test_primitive_witnesses_by_hand():
    # Sphere r = 0.1 at the origin, box 0.2 wide centred at x = 0.5: closest points on the x axis.
    scene = pair_scene(sphere(0.1), np.eye(4), box((0.2, 0.2, 0.2)), rigid(np.eye(3), [0.5, 0, 0]))
    w = scene.witnesses([0.0])
    assert w.distance[0, 0] == pytest.approx(0.3, abs=1e-9)
    np.testing.assert_allclose(w.on_link[0, 0], [0.1, 0, 0], atol=1e-7)
    np.testing.assert_allclose(w.on_obstacle[0, 0], [0.4, 0, 0], atol=1e-7)
    # The link moves with its prismatic joint: q = 0.25 lifts it.
    d = scene.distances([0.25])[0, 0]
    assert d == pytest.approx(math.hypot(0.4, 0.15) - 0.1, abs=1e-9)


# ----- several shapes per link and per obstacle -------------------------------------------------


def test_cells_take_the_minimum_over_parts():
    link = one_link_robot(
        [sphere(0.05), sphere(0.05)], [rigid(np.eye(3), [0, 0, 0]), rigid(np.eye(3), [1, 0, 0])]
    )
    obstacles = [
        Obstacle("near", (sphere(0.1), sphere(0.1)), rigid(np.eye(3), [0.0, 0.5, 0.0])),
        Obstacle("far", (sphere(0.1),), rigid(np.eye(3), [1.0, 0.0, 2.0])),
    ]
    scene = Scene(link, obstacles)
    assert scene.link_names == ["link"]
    d = scene.distances([0.0])
    assert d.shape == (1, 2)
    assert d[0, 0] == pytest.approx(0.5 - 0.15, abs=1e-9)
    assert d[0, 1] == pytest.approx(2.0 - 0.15, abs=1e-9)
    assert scene.min_distance([0.0]) == pytest.approx(0.35, abs=1e-9)


# ----- broad phase ------------------------------------------------------------------------------

U_OUTLINE = 0.1 * np.array(
    [(0, 0), (3, 0), (3, 1), (3, 2), (2, 2), (2, 1), (1, 1), (1, 2), (0, 2), (0, 1)], float
)
U_TRIANGLES = np.array(
    [(0, 1, 2), (0, 2, 5), (0, 5, 6), (0, 6, 9), (5, 2, 3), (5, 3, 4), (9, 6, 7), (9, 7, 8)]
)


def _busy_scene_spec(folder: Path) -> dict:
    """The iiwa14 among a decomposed U, moving primitives and the two example meshes."""
    u = trimesh.creation.extrude_triangulation(U_OUTLINE, U_TRIANGLES, 0.1)
    u.export(folder / "u.obj")  # OBJ keeps shared vertices: a closed mesh for CoACD
    for name in ("bracket.stl", "rock.stl"):
        (folder / name).write_bytes((CONFIGS / name).read_bytes())
    obstacles = [
        {"name": "u", "mesh": "u.obj", "decompose": True, "scale": 2.0,
         "position": [0.2, -0.3, 0.5], "rpy": [0.0, 0.3, 0.0]},
        {"name": "ball", "sphere": 0.1, "position": [0.5, -0.5, 0.6], "velocity": [-0.2, 0.3, 0.0]},
        {"name": "crate", "box": [0.2, 0.1, 0.3], "position": [-0.4, -0.3, 0.5],
         "rpy": [0.1, 0.2, 0.3], "velocity": [0.1, 0.1, 0.05]},
        {"name": "rod", "capsule": [0.05, 0.4], "position": [0.0, 0.5, 1.0]},
        {"name": "pipe", "cylinder": [0.05, 0.6], "position": [0.3, -0.3, 1.2],
         "rpy": [1.2, 0.0, 0.0]},
        {"name": "bracket", "mesh": "bracket.stl", "position": [0.3, 0.4, 0.45]},
        {"name": "rock", "mesh": "rock.stl", "position": [-0.25, 0.45, 0.8],
         "velocity": [0.0, 0.0, -0.1]},
    ]  # fmt: skip
    return {"robot": {"builtin": "iiwa14"}, "obstacles": obstacles}


@pytest.fixture(scope="module")
def busy(tmp_path_factory) -> tuple[dict, Path]:
    folder = tmp_path_factory.mktemp("busy")
    return _busy_scene_spec(folder), folder


@pytest.fixture(scope="module")
def busy_scenes(busy) -> tuple[Scene, Scene]:
    data, folder = busy
    spec = load_scene_spec({**data, "robot": {**data["robot"], "self_collision": False}})
    with_bp, _ = build_scene(spec, folder, broadphase=True)
    without, _ = build_scene(spec, folder, broadphase=False)
    return with_bp, without


@pytest.fixture(scope="module")
def example_scenes() -> tuple[Scene, Scene]:
    data = load_toml(TWO_OBSTACLES)
    data["robot"]["self_collision"] = False  # link-obstacle distances alone
    spec = load_scene_spec(data)
    with_bp, _ = build_scene(spec, CONFIGS, broadphase=True)
    without, _ = build_scene(spec, CONFIGS, broadphase=False)
    return with_bp, without


NO_SELF = {"builtin": "iiwa14", "self_collision": False}  # link-obstacle distances alone


def _random_configurations(robot: RobotModel, n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(robot.lower, robot.upper, size=(n, robot.nq))


def test_broadphase_is_exact_on_the_example_scene(example_scenes):
    fast, full = example_scenes
    assert fast.broadphase and not full.broadphase
    Q = _random_configurations(fast.robot, 300, seed=1)
    mins = []
    for q in Q:
        d_fast, d_full = fast.distances(q), full.distances(q)
        assert np.array_equal(d_fast, d_full), q
        m = fast.min_distance(q)
        assert m == full.min_distance(q) == d_full.min(), q
        mins.append(m)
    # Both regimes were exercised: collisions and free configurations.
    assert min(mins) < 0 < max(mins)
    assert np.array_equal(fast.min_distance_batch(Q), full.min_distance_batch(Q))
    assert np.array_equal(fast.distances_batch(Q[:20]), full.distances_batch(Q[:20]))


def test_broadphase_is_exact_with_parts_and_moving_obstacles(busy_scenes):
    fast, full = busy_scenes
    parts = {o.name: len(o.parts) for o in fast.obstacles}
    assert parts["u"] >= 2
    assert {o.name for o in fast.obstacles if o.moving} == {"ball", "crate", "rock"}
    Q = _random_configurations(fast.robot, 200, seed=2)
    negatives = 0
    for t in (0.0, 0.7, 2.5, 6.0):
        for q in Q:
            d_fast, d_full = fast.distances(q, t), full.distances(q, t)
            assert np.array_equal(d_fast, d_full), (q, t)
            m = fast.min_distance(q, t)
            assert m == full.min_distance(q, t) == d_full.min(), (q, t)
            negatives += m < 0
        assert np.array_equal(fast.min_distance_batch(Q, t), full.min_distance_batch(Q, t))
    assert 0 < negatives < 4 * len(Q)


def test_batch_shapes_and_errors(example_scenes):
    scene, _ = example_scenes
    Q = _random_configurations(scene.robot, 3, seed=3)
    assert scene.distances_batch(Q).shape == (3, 8, 2)
    assert scene.min_distance_batch(Q).shape == (3,)
    for bad in (np.zeros(7), np.zeros((2, 6))):
        with pytest.raises(ConfigError) as exc:
            scene.min_distance_batch(bad)
        assert exc.value.field == "Q"


# ----- the book's vertex metric -----------------------------------------------------------------


def _brute_vertex_distances(scene: Scene, q: np.ndarray, t: float) -> np.ndarray:
    """Closest vertex pair per (link, obstacle) cell, by cdist over world vertices."""
    poses_ = scene.robot.link_poses(q)
    out = np.full((len(scene.robot.links), len(scene.obstacles)), np.inf)
    for li, link in enumerate(scene.robot.links):
        link_points = [
            world(poses_[link.name] @ T, s.vertices)
            for s, T in zip(link.shapes, link.placements, strict=True)
        ]
        for oi, obstacle in enumerate(scene.obstacles):
            T = obstacle.pose_at(t)
            for part in obstacle.parts:
                for pts in link_points:
                    out[li, oi] = min(out[li, oi], cdist(pts, world(T, part.vertices)).min())
    return out


@pytest.mark.parametrize("which", ["example", "busy"])
def test_vertex_metric_is_the_brute_force_vertex_minimum(which, busy):
    if which == "example":
        spec, folder = load_scene_spec(load_toml(TWO_OBSTACLES) | {"robot": NO_SELF}), CONFIGS
    else:
        spec, folder = load_scene_spec(busy[0] | {"robot": NO_SELF}), busy[1]
    vertex, _ = build_scene(spec, folder, metric="vertex")
    gjk, _ = build_scene(spec, folder, metric="gjk")
    Q = _random_configurations(vertex.robot, 25, seed=4)
    separated = 0
    for i, q in enumerate(Q):
        t = 0.5 * i
        d_vertex = vertex.distances(q, t)
        np.testing.assert_allclose(d_vertex, _brute_vertex_distances(vertex, q, t), atol=1e-12)
        assert vertex.min_distance(q, t) == d_vertex.min()
        d_gjk = gjk.distances(q, t)
        apart = d_gjk > 0
        separated += apart.sum()
        # Never below the true distance; GJK itself stops within its tolerance (1e-6) of it.
        assert np.all(d_vertex[apart] >= d_gjk[apart] - GJK_TOL)
        assert np.all(d_vertex >= 0)
    assert separated > 0


def test_vertex_metric_overstates_a_face_to_face_gap():
    # Two 1 m cubes, faces 0.1 m apart but shifted by half a side: the nearest vertices are
    # sqrt(0.1² + 0.5²) apart (Sect. 1.3.3 of the book; docs/deviations.md).
    a, b = box((1.0, 1.0, 1.0)), box((1.0, 1.0, 1.0))
    Tb = rigid(np.eye(3), [1.1, 0.5, 0.0])
    robot = one_link_robot([a], [np.eye(4)])
    vertex = Scene(robot, [Obstacle("b", (b,), Tb)], metric="vertex")
    gjk = Scene(robot, [Obstacle("b", (b,), Tb)])
    assert gjk.distances([0.0])[0, 0] == pytest.approx(0.1, abs=1e-9)
    assert vertex.distances([0.0])[0, 0] == pytest.approx(math.hypot(0.1, 0.5), abs=1e-12)
    w = vertex.witnesses([0.0])
    assert np.linalg.norm(w.on_link[0, 0] - w.on_obstacle[0, 0]) == pytest.approx(
        math.hypot(0.1, 0.5), abs=1e-12
    )
    assert any(np.allclose(w.on_link[0, 0], v) for v in a.vertices)
    assert any(np.allclose(w.on_obstacle[0, 0], world(Tb, v[None])[0]) for v in b.vertices)


# ----- refusals and edge cases ------------------------------------------------------------------


def test_obstacle_names_must_be_unique():
    part = (sphere(0.1),)
    robot = one_link_robot([sphere(0.1)], [np.eye(4)])
    with pytest.raises(ConfigError) as exc:
        Scene(robot, [Obstacle("x", part, np.eye(4)), Obstacle("x", part, np.eye(4))])
    assert exc.value.field == "obstacles"


def test_unknown_metric_is_refused():
    robot = one_link_robot([sphere(0.1)], [np.eye(4)])
    with pytest.raises(ConfigError) as exc:
        Scene(robot, [], metric="euclid")  # type: ignore[arg-type]
    assert exc.value.field == "metric"


def test_a_configuration_of_the_wrong_size_is_refused():
    scene = Scene(one_link_robot([sphere(0.1)], [np.eye(4)]), [])
    with pytest.raises(ConfigError):
        scene.distances([0.0, 0.0])


def test_scene_without_obstacles():
    scene = Scene(one_link_robot([sphere(0.1)], [np.eye(4)]), [])
    assert scene.distances([0.0]).shape == (1, 0)
    assert scene.min_distance([0.0]) == math.inf


def test_example_scene_at_home(example_scenes):
    scene, _ = example_scenes
    d = scene.distances(np.zeros(7))
    assert d.shape == (8, 2)
    assert np.all(d > 0.15)  # the arm stands clear of both obstacles at home
    # The bracket sits 0.4 m in front at 0.3-0.6 m height: link 2 (the shoulder) is nearest.
    assert int(np.argmin(d[:, 0])) == 2
