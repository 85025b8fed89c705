"""Scene: a robot among obstacles, with signed link-obstacle distances (GJK/EPA via coal) and,
for the link pairs it is given, link-link (self) distances.

Robot link shapes and obstacle parts live in one Pinocchio GeometryModel, one collision pair
per (link shape, obstacle part) and per (shape, shape) of a checked link pair, so forward
kinematics, placements and every exact distance run in C++. A second model holds a bounding
capsule per shape: capsule-capsule distances (closed form in coal) are lower bounds of the
exact ones, which lets the broad phase skip pairs that cannot be the minimum.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import coal
import numpy as np
import pinocchio as pin
from scipy.spatial import cKDTree

from articula.errors import ConfigError
from articula.geometry.poses import transform_points
from articula.geometry.shapes import ConvexShape
from articula.robots.model import RobotModel
from articula.scene._pair_distances import _PairDistances
from articula.scene.obstacles import Obstacle
from articula.scene.pairs import SelfWitnesses, Witnesses, link_pairs

Metric = Literal["gjk", "vertex"]
SELF_D_MIN = 0.005  # [m] default clearance kept between the links of a checked pair


class _Geometry:
    """The exact and bounding-capsule geometry models with matching objects and pairs."""

    def __init__(self) -> None:
        self.exact = pin.GeometryModel()
        self.bounds = pin.GeometryModel()
        self.shapes: list[ConvexShape] = []

    def add(self, name: str, joint: int, frame: int, placement: pin.SE3, shape: ConvexShape) -> int:
        self.exact.addGeometryObject(
            pin.GeometryObject(name, joint, frame, placement, shape.geometry)
        )
        b = shape.bound
        bound = pin.GeometryObject(
            name, joint, frame, placement * pin.SE3(b.pose), coal.Capsule(b.radius, b.length)
        )
        self.bounds.addGeometryObject(bound)
        self.shapes.append(shape)
        return len(self.shapes) - 1

    def pair(self, a: int, b: int) -> None:
        self.exact.addCollisionPair(pin.CollisionPair(a, b))
        self.bounds.addCollisionPair(pin.CollisionPair(a, b))


class Scene(_PairDistances):
    """A robot and its obstacles; distances for a joint configuration q at time t [s].

    Args:
        robot: the arm; its links' collision shapes are measured.
        obstacles: the obstacles, each with a unique name.
        broadphase: whether queries skip the pairs whose bounding capsules show they cannot be
            a minimum (metric "gjk").
        metric: "gjk": signed distance between convex shapes, negative penetration depth when
            they overlap. "vertex": the book's Sect. 1.3.3 formula, the distance between the
            closest pair of vertices, which over-states clearance (docs/deviations.md).
        self_pairs: the link pairs (by name) whose distance counts as clearance too, usually
            self_collision_matrix(robot).checked (the pairs not adjacent that can come close).
        self_d_min: the clearance [m] every planner keeps between the links of a checked pair,
            as d_min (Eq. 1.12) between links and obstacles.
    """

    def __init__(
        self,
        robot: RobotModel,
        obstacles: Sequence[Obstacle],
        broadphase: bool = True,
        metric: Metric = "gjk",
        self_pairs: Sequence[tuple[str, str]] = (),
        self_d_min: float = SELF_D_MIN,
    ) -> None:
        if metric not in ("gjk", "vertex"):
            raise ConfigError("metric", f"unknown metric {metric!r}; choose 'gjk' or 'vertex'")
        names = [o.name for o in obstacles]
        if len(set(names)) != len(names):
            raise ConfigError("obstacles", f"obstacle names must be unique (got {names})")
        self.robot = robot
        self.obstacles = tuple(obstacles)
        self.broadphase = broadphase
        self.metric: Metric = metric
        self.link_names = [link.name for link in robot.links]
        self.self_pairs = link_pairs(self_pairs, self.link_names, "self_pairs")
        if not (np.isfinite(self_d_min) and self_d_min >= 0):
            raise ConfigError("self_d_min", f"must be finite and >= 0 m (got {self_d_min})")
        self.self_d_min = float(self_d_min)
        geo = _Geometry()
        link_geoms = []
        for li, link in enumerate(robot.links):
            frame = robot.model.frames[link.frame_id]
            for si, (shape, T) in enumerate(zip(link.shapes, link.placements, strict=True)):
                g = geo.add(
                    f"{link.name}/{si}",
                    frame.parentJoint,
                    link.frame_id,
                    frame.placement * pin.SE3(T),
                    shape,
                )
                link_geoms.append((g, li))
        self._obstacle_geoms = []
        for obstacle in self.obstacles:
            world = pin.SE3(obstacle.pose_at(0.0))
            self._obstacle_geoms.append(
                [
                    geo.add(f"{obstacle.name}/{k}", 0, 0, world, p)
                    for k, p in enumerate(obstacle.parts)
                ]
            )
        cells = []
        static = []  # pairs whose placements never change: world-fixed link, still obstacle
        for g_link, li in link_geoms:
            for oi, parts in enumerate(self._obstacle_geoms):
                for g_obstacle in parts:
                    geo.pair(g_link, g_obstacle)
                    cells.append((li, oi))
                    fixed = geo.exact.geometryObjects[g_link].parentJoint == 0
                    static.append(fixed and not self.obstacles[oi].moving)
        self._n_obstacle_pairs = len(cells)
        # Self pairs follow, one per (shape of a, shape of b); their cell is (-1, pair index).
        self_cells = []
        shapes_of: dict[int, list[int]] = {}
        for g, li in link_geoms:
            shapes_of.setdefault(li, []).append(g)
        for k, (a, b) in enumerate(self.self_pairs):
            for g_a in shapes_of.get(a, []):
                for g_b in shapes_of.get(b, []):
                    geo.pair(g_a, g_b)
                    cells.append((-1, k))
                    self_cells.append(k)
                    joints = {geo.exact.geometryObjects[g].parentJoint for g in (g_a, g_b)}
                    static.append(joints == {0})
        self._geo = geo
        self._cells = np.array(cells[: self._n_obstacle_pairs], dtype=np.int64).reshape(-1, 2)
        self._self_cells = np.array(self_cells, dtype=np.int64)
        self._exact_data = pin.GeometryData(geo.exact)
        self._bounds_data = pin.GeometryData(geo.bounds)
        # Element proxies made once: reading through them is several times cheaper.
        self._results = list(self._exact_data.distanceResults)
        self._requests = list(self._exact_data.distanceRequests)
        self._bound_results = list(self._bounds_data.distanceResults)
        for request in self._requests:
            request.enable_signed_distance = True  # EPA penetration depth when overlapping
        self._cell_of_pair = cells
        self._trees = [cKDTree(s.vertices) for s in geo.shapes]
        self._moving = [oi for oi, o in enumerate(self.obstacles) if o.moving]
        self._shape = (len(robot.links), len(self.obstacles))
        # The broad phase computes static pairs once and leaves them out of every query.
        self._place(np.zeros(robot.nq), 0.0)
        kind_of = [int(p >= self._n_obstacle_pairs) for p in range(len(static))]  # 1: self
        self._static_min = [np.inf, np.inf]
        for p, fixed in enumerate(static):
            if fixed:
                self._static_min[kind_of[p]] = min(self._static_min[kind_of[p]], self._exact(p))
        self._dynamic = [p for p, fixed in enumerate(static) if not fixed]
        self._dynamic_kinds = [kind_of[p] for p in self._dynamic]
        self._kinds_present = sorted(set(self._dynamic_kinds))  # kinds a query can lower
        self._dynamic_bounds = [self._bound_results[p] for p in self._dynamic]
        for p, fixed in enumerate(static):
            if fixed:
                self._bounds_data.deactivateCollisionPair(p)

    @property
    def self_pair_names(self) -> list[tuple[str, str]]:
        """The checked link pairs by name, in the order of self_distances."""
        return [(self.link_names[a], self.link_names[b]) for a, b in self.self_pairs]

    @property
    def has_clearance(self) -> bool:
        """Whether any distance is checked: an obstacle, or a link pair for self-collision."""
        return bool(self.obstacles or self.self_pairs)

    # ----- queries -----------------------------------------------------------------------------

    def distances(self, q: Sequence[float] | np.ndarray, t: float = 0.0) -> np.ndarray:
        """Signed distance [m] from every link (rows) to every obstacle (columns).

        Args:
            q: joint positions, nq values [rad or m].
            t: time, for the poses of moving obstacles [s].

        Returns:
            The distances, shape (links, obstacles) [m].
        """
        return self._cell_minima(self._pair_distances(self.robot.check_q(q), t))

    def witnesses(self, q: Sequence[float] | np.ndarray, t: float = 0.0) -> Witnesses:
        """Distances with the closest point on the link and on the obstacle for each cell.

        Args:
            q: joint positions, nq values [rad or m].
            t: time, for the poses of moving obstacles [s].

        Returns:
            The distances and closest points of every (link, obstacle) cell.
        """
        return self.witnesses_within(q, t)[0]

    def witnesses_within(
        self, q: Sequence[float] | np.ndarray, t: float = 0.0, within: float = np.inf
    ) -> tuple[Witnesses, SelfWitnesses]:
        """Witnesses of every cell and of every checked link pair, from one pass; with the
        broad phase, a pair whose capsules are `within` [m] or farther apart is not computed,
        so a cell or link pair farther than that may read +inf (a controller that only acts
        below an influence distance asks for no more).

        Args:
            q: joint positions, nq values [rad or m].
            t: time, for the poses of moving obstacles [s].
            within: capsule distance from which a pair is not computed [m].

        Returns:
            (witnesses of the link-obstacle cells, witnesses of the checked link pairs).
        """
        d = self._pair_distances(self.robot.check_q(q), t, every_pair=True, within=within)
        return self._witnesses(d), self._self_witnesses(d)

    def _witnesses(self, d: list[float]) -> Witnesses:
        on_link = np.full((*self._shape, 3), np.nan)
        on_obstacle = np.full((*self._shape, 3), np.nan)
        best = np.full(self._shape, np.inf)
        for p, (li, oi) in enumerate(self._cell_of_pair[: self._n_obstacle_pairs]):
            if d[p] < best[li, oi]:
                best[li, oi] = d[p]
                on_link[li, oi], on_obstacle[li, oi] = self._closest_points(p)
        return Witnesses(best, on_link, on_obstacle)

    def self_distances(self, q: Sequence[float] | np.ndarray) -> np.ndarray:
        """Signed distance [m] of every link pair in `self_pairs`, in its order.

        Args:
            q: joint positions, nq values [rad or m].

        Returns:
            The distances, shape (pairs,) [m].
        """
        return self._self_minima(self._pair_distances(self.robot.check_q(q), 0.0, True))

    def self_witnesses(self, q: Sequence[float] | np.ndarray) -> SelfWitnesses:
        """Self distances with the closest point on each link of each pair.

        Args:
            q: joint positions, nq values [rad or m].

        Returns:
            The distances and closest points of the checked link pairs.
        """
        return self.witnesses_within(q)[1]

    def _self_witnesses(self, d: list[float]) -> SelfWitnesses:
        n = len(self.self_pairs)
        best, on_a, on_b = np.full(n, np.inf), np.full((n, 3), np.nan), np.full((n, 3), np.nan)
        for p in range(self._n_obstacle_pairs, len(d)):
            k = self._cell_of_pair[p][1]
            if d[p] < best[k]:
                best[k] = d[p]
                on_a[k], on_b[k] = self._closest_points(p)
        return SelfWitnesses(best, on_a, on_b)

    def self_clearance(self, q: Sequence[float] | np.ndarray) -> float:
        """Smallest signed distance [m] between two links of a checked pair (inf without any).

        Args:
            q: joint positions, nq values [rad or m].

        Returns:
            The self clearance [m].
        """
        return float(np.min(self.self_distances(q), initial=np.inf))

    def min_distance(self, q: Sequence[float] | np.ndarray, t: float = 0.0) -> float:
        """Smallest signed distance [m] between any link and any obstacle, or between the two
        links of a checked self pair.

        Args:
            q: joint positions, nq values [rad or m].
            t: time, for the poses of moving obstacles [s].

        Returns:
            The clearance [m] (+inf without any pair).
        """
        return min(self.clearances(q, t))

    def clearances(self, q: Sequence[float] | np.ndarray, t: float = 0.0) -> tuple[float, float]:
        """(smallest link-obstacle distance, smallest distance of a checked link pair) [m];
        +inf for a kind without pairs.

        Args:
            q: joint positions, nq values [rad or m].
            t: time, for the poses of moving obstacles [s].

        Returns:
            (obstacle clearance, self clearance) [m].
        """
        q = self.robot.check_q(q)
        if self.broadphase and self.metric == "gjk":
            return self._min_broadphase(q, t)
        d = self._pair_distances(q, t, every_pair=True)
        n = self._n_obstacle_pairs
        return float(np.min(d[:n], initial=np.inf)), float(np.min(d[n:], initial=np.inf))

    def distances_batch(self, Q: np.ndarray, t: float = 0.0) -> np.ndarray:
        """distances() for each row of Q: an array (configurations, links, obstacles).

        Args:
            Q: joint configurations, shape (n, nq) [rad or m].
            t: time, for the poses of moving obstacles [s].

        Returns:
            The distances, shape (n, links, obstacles) [m].
        """
        return np.stack([self.distances(q, t) for q in self._check_batch(Q)])

    def min_distance_batch(self, Q: np.ndarray, t: float = 0.0) -> np.ndarray:
        """min_distance() for each row of Q.

        Args:
            Q: joint configurations, shape (n, nq) [rad or m].
            t: time, for the poses of moving obstacles [s].

        Returns:
            The clearances, shape (n,) [m].
        """
        return np.array([self.min_distance(q, t) for q in self._check_batch(Q)])

    # ----- internals ---------------------------------------------------------------------------

    def _check_batch(self, Q: np.ndarray) -> np.ndarray:
        arr = np.asarray(Q, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != self.robot.nq:
            raise ConfigError("Q", f"needs shape (n, {self.robot.nq}) (got {arr.shape})")
        return arr

    def _move_obstacles(self, t: float) -> None:
        """Put moving obstacles (exact shapes and bounding capsules) at their pose at time t."""
        for oi in self._moving:
            world = pin.SE3(self.obstacles[oi].pose_at(t))
            for g in self._obstacle_geoms[oi]:
                self._geo.exact.geometryObjects[g].placement = world
                bound = pin.SE3(self._geo.shapes[g].bound.pose)
                self._geo.bounds.geometryObjects[g].placement = world * bound

    def _place(self, q: np.ndarray, t: float) -> None:
        """Forward kinematics and every exact shape placement, obstacles at time t."""
        self._move_obstacles(t)
        pin.updateGeometryPlacements(
            self.robot.model, self.robot.data, self._geo.exact, self._exact_data, q
        )

    def _cell_minima(self, pair_distances: list[float]) -> np.ndarray:
        out = np.full(self._shape, np.inf)
        obstacle_pairs = pair_distances[: self._n_obstacle_pairs]
        np.minimum.at(out, (self._cells[:, 0], self._cells[:, 1]), obstacle_pairs)
        return out

    def _self_minima(self, pair_distances: list[float]) -> np.ndarray:
        out = np.full(len(self.self_pairs), np.inf)
        np.minimum.at(out, self._self_cells, pair_distances[self._n_obstacle_pairs :])
        return out

    def _closest_points(self, p: int) -> tuple[np.ndarray, np.ndarray]:
        """The closest points (world) of pair p's two shapes, by the scene's metric."""
        if self.metric == "gjk":
            return self._results[p].getNearestPoint1(), self._results[p].getNearestPoint2()
        return self._vertex_pair(p)

    def _vertex_pair(self, p: int) -> tuple[np.ndarray, np.ndarray]:
        """Closest vertex pair (world) of pair p, the book's Sect. 1.3.3 formula."""
        pair = self._geo.exact.collisionPairs[p]
        a, b = pair.first, pair.second
        Ta = self._exact_data.oMg[a].homogeneous
        Tb = self._exact_data.oMg[b].homogeneous
        # Query b's tree with a's vertices expressed in b's frame.
        va_in_b = transform_points(np.linalg.inv(Tb) @ Ta, self._geo.shapes[a].vertices)
        dist, idx = self._trees[b].query(va_in_b)
        i = int(np.argmin(dist))
        on_a = transform_points(Ta, self._geo.shapes[a].vertices[i : i + 1])[0]
        on_b = transform_points(Tb, self._geo.shapes[b].vertices[idx[i] : idx[i] + 1])[0]
        return on_a, on_b

    def _vertex_distance(self, p: int) -> float:
        on_a, on_b = self._vertex_pair(p)
        return float(np.linalg.norm(on_a - on_b))
