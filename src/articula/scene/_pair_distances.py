"""Scene's passes over its collision pairs: the exact signed distance of one pair, capsule
lower bounds of every pair, and the broad phase that skips the pairs that cannot be a minimum.

A base of Scene, which sets up the geometry models, placements and pair lists these read.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

_NO_SUPPORT_GUESS = np.zeros(2, dtype=np.int32)
_NO_GJK_GUESS = np.array([1.0, 0.0, 0.0])


class _PairDistances:
    """Distance passes of Scene over its collision pairs (Scene builds what they read)."""

    def _exact(self, p: int) -> float:
        """Signed distance of pair p at the current placements, independent of earlier calls.

        coal warm-starts GJK from the previous answer of the same pair; resetting the guess
        makes every answer a function of the placements alone, so the broad phase and the
        full loop give bit-identical numbers.
        """
        request = self._requests[p]
        request.cached_support_func_guess = _NO_SUPPORT_GUESS
        request.cached_gjk_guess = _NO_GJK_GUESS
        pin.computeDistance(self._geo.exact, self._exact_data, p)
        return self._results[p].min_distance

    def self_distances_of(self, q: np.ndarray, pairs: Sequence[int]) -> np.ndarray:
        """Signed distance [m] of some of the checked link pairs alone (exact, GJK metric).

        Args:
            q: joint positions, shape (nq,) [rad or m] (unchecked).
            pairs: indices into `self_pairs`.

        Returns:
            Their distances, in the order of `pairs`, shape (len(pairs),) [m].
        """
        if not hasattr(self, "_geometry_of_self_pair"):
            self._geometry_of_self_pair: dict[int, list[int]] = {}
            for p in range(self._n_obstacle_pairs, len(self._cell_of_pair)):
                self._geometry_of_self_pair.setdefault(self._cell_of_pair[p][1], []).append(p)
        self._place(q, 0.0)
        return np.array(
            [min(self._exact(p) for p in self._geometry_of_self_pair[k]) for k in pairs]
        )

    def _pair_distances(
        self, q: np.ndarray, t: float, every_pair: bool = False, within: float = np.inf
    ) -> list[float]:
        """Distance of every pair; with the broad phase, pairs that cannot be the minimum of
        their cell are left at +inf unless `every_pair`, and with `every_pair` those whose
        lower bound is `within` [m] or more."""
        n = len(self._cell_of_pair)
        if self.metric == "vertex":
            self._place(q, t)
            return [self._vertex_distance(p) for p in range(n)]
        if every_pair and self.broadphase and within < np.inf:
            lower = self._lower_bounds(q, t)
            pin.updateGeometryPlacements(
                self.robot.model, self.robot.data, self._geo.exact, self._exact_data
            )
            return [self._exact(p) if lower[p] < within else np.inf for p in range(n)]
        if every_pair or not self.broadphase:
            self._place(q, t)
            return [self._exact(p) for p in range(n)]
        lower = self._lower_bounds(q, t)
        pin.updateGeometryPlacements(
            self.robot.model, self.robot.data, self._geo.exact, self._exact_data
        )
        out = [np.inf] * n
        cell_best: dict[tuple[int, int], float] = {}
        for p in sorted(range(n), key=lower.__getitem__):
            cell = self._cell_of_pair[p]
            if lower[p] >= cell_best.get(cell, np.inf):
                continue
            out[p] = self._exact(p)
            cell_best[cell] = min(cell_best.get(cell, np.inf), out[p])
        return out

    def _lower_bounds(self, q: np.ndarray, t: float) -> list[float]:
        """Capsule-capsule distances of every pair (lower bounds of the exact ones; -inf for the
        static pairs, which the bounds model skips); also runs the forward kinematics that the
        exact placements then reuse."""
        self._move_obstacles(t)
        pin.computeDistances(
            self.robot.model, self.robot.data, self._geo.bounds, self._bounds_data, q
        )
        lower = [-np.inf] * len(self._bound_results)  # static pairs: no bound, always exact
        for p, r in zip(self._dynamic, self._dynamic_bounds, strict=True):
            lower[p] = r.min_distance
        return lower

    def _min_broadphase(self, q: np.ndarray, t: float) -> tuple[float, float]:
        # The hot path of the planner: attribute lookups are hoisted, _exact is inlined.
        if self._moving:
            self._move_obstacles(t)
        model, data = self.robot.model, self.robot.data
        pin.computeDistances(model, data, self._geo.bounds, self._bounds_data, q)
        lower = [r.min_distance for r in self._dynamic_bounds]
        exact_model, exact_data = self._geo.exact, self._exact_data
        pin.updateGeometryPlacements(model, data, exact_model, exact_data)
        requests, results, dynamic = self._requests, self._results, self._dynamic
        best = list(self._static_min)  # [obstacles, self]
        kinds, present = self._dynamic_kinds, self._kinds_present
        # Visit pairs by increasing lower bound; none after the first bound above the best
        # exact distance so far of every kind can lower a minimum.
        for i in sorted(range(len(lower)), key=lower.__getitem__):
            kind = kinds[i]
            if lower[i] >= best[kind]:
                if all(lower[i] >= best[k] for k in present):
                    break
                continue
            p = dynamic[i]
            request = requests[p]
            request.cached_support_func_guess = _NO_SUPPORT_GUESS  # as in _exact
            request.cached_gjk_guess = _NO_GJK_GUESS
            pin.computeDistance(exact_model, exact_data, p)
            d = results[p].min_distance
            if d < best[kind]:
                best[kind] = d
        return float(best[0]), float(best[1])
