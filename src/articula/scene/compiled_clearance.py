"""The planner's hot path in one compiled call: forward kinematics, the end-effector position
and the smallest link-obstacle clearance, with the same capsule broad phase as Scene.

One BAORNN iteration evaluates the objective three times; through Pinocchio and coal each
evaluation is a dozen Python-level calls into C++ (about 1 µs each, see docs/architecture.md).
Here the whole evaluation is one numba function over arrays taken from the same Scene. It
covers the common case (revolute joints; polytope, sphere and capsule shapes) and
`CompiledClearance.build` returns None otherwise, so callers fall back to Scene.min_distance.
A moving obstacle (a velocity, or a live pose) is put at its pose of time t by `at(t)`
before the evaluations of that time. Clearance is GJK distance, and 0 when shapes overlap
(no depth); the obstacle clearance and the self clearance (the scene's checked link pairs)
come out apart.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from articula.numba_cache import jit
from articula.scene._compiled_arrays import _capsule_ends, _core, _edges, _pair_rows, _reach
from articula.scene._compiled_pruning import _near_pairs
from articula.scene.compiled_bundles import Chain, Scratch, Shapes, named_inputs, packed
from articula.scene.compiled_poses import (
    _ee_pose,
    _joint_poses,
    _moved,
    _place_ends,
    _remember,
    _remembered_bound,
    _segment_distance,
    _shape_poses,
)
from articula.scene.gjk import gjk_distance
from articula.scene.scene import Scene

OBSTACLE, SELF = 0, 1  # the kinds of pair: link-obstacle, link-link
_AXES = {"JointModelRX": (1.0, 0.0, 0.0), "JointModelRY": (0.0, 1.0, 0.0),
         "JointModelRZ": (0.0, 0.0, 1.0)}  # fmt: skip


class CompiledClearance:
    """A Scene as arrays for `evaluate`: kinematic chain, shape cores, capsules and pairs.

    Not frozen: `scratch` changes at every evaluation, and a moving obstacle's pose in
    `shapes` at every `at(t)`.

    Args:
        chain: the kinematic chain (never changes).
        shapes: the link shapes, then the obstacle parts.
        pairs: rows (shape a, shape b, scratch row, OBSTACLE | SELF, cell) of the pairs that
            move, shape (pairs, 5).
        rows: how many scratch rows the pairs use (moving and fixed).
        cells: number of cells: (link, obstacle) cells row-major, then the checked link pairs.
        reach: no shape point is farther than this from any joint origin, in any pose [m].
        moving_parts: (shape index, its obstacle) of each part of a moving obstacle.

    Attributes:
        scratch: what the evaluations remember (GJK warm starts, the pairs' last bounds).
        static_min: smallest distance of the pairs that never move, per kind, shape (2,) [m]
            (+inf until `build` measures them).
    """

    def __init__(
        self,
        chain: Chain,
        shapes: Shapes,
        pairs: np.ndarray,
        rows: int,
        cells: int,
        reach: float,
        moving_parts: tuple[tuple[int, object], ...] = (),
    ) -> None:
        self.chain, self.shapes, self.pairs, self.cells = chain, shapes, pairs, cells
        self.reach, self.moving_parts = reach, moving_parts
        self.scratch = Scratch.fresh(shapes.starts, rows)
        self._packed = packed((chain, shapes, self.scratch))  # the same arrays, built once
        self.static_min = np.full(2, np.inf)
        self._selected: dict = {}  # select's answers, by kinds

    @classmethod
    def build(cls, scene: Scene) -> CompiledClearance | None:
        """The arrays of `scene`, or None when it needs something this path does not cover.

        Args:
            scene: the scene to compile.

        Returns:
            Its arrays; None for the vertex metric, a joint that is not revolute or a cylinder.
        """
        model = scene.robot.model
        names = [model.joints[j].shortname() for j in range(1, model.njoints)]
        if scene.metric != "gjk":
            return None
        if any(name not in _AXES and name != "JointModelRevoluteUnaligned" for name in names):
            return None
        shapes, joints, poses, owner, part_of, moving_parts = [], [], [], [], [], []
        # Without anything to keep clear of only the kinematics are needed: no shape at all.
        for li, link in enumerate(scene.robot.links if scene.has_clearance else ()):
            frame = model.frames[link.frame_id]
            for shape, T in zip(link.shapes, link.placements, strict=True):
                shapes.append(shape)
                joints.append(frame.parentJoint)
                poses.append((frame.placement * pin.SE3(T)).homogeneous)
                owner.append(li)
        n_links = len(shapes)
        for oi, obstacle in enumerate(scene.obstacles):
            for part in obstacle.parts:
                if obstacle.moving:
                    moving_parts.append((len(shapes), obstacle))
                shapes.append(part)
                joints.append(0)
                poses.append(obstacle.pose_at(0.0))
                part_of.append(oi)
        cores = [_core(s) for s in shapes]
        if any(c is None for c in cores):
            return None
        starts = np.cumsum([0] + [len(c[0]) for c in cores]).astype(np.int64)
        neighbours, offsets = _edges([c[0] for c in cores], starts)
        axes = np.zeros((model.njoints, 3))
        for j in range(1, model.njoints):
            joint = model.joints[j]
            name = joint.shortname()
            axes[j] = _AXES[name] if name in _AXES else joint.extract().axis
        bounds = [_capsule_ends(s) for s in shapes]
        n_obstacles = len(scene.obstacles)
        cell_count = len(scene.robot.links) * n_obstacles + len(scene.self_pairs)
        pairs = [(a, b, OBSTACLE, owner[a] * n_obstacles + part_of[b - n_links])
                 for a in range(n_links) for b in range(n_links, len(shapes))]  # fmt: skip
        pairs += [(a, b, SELF, cell_count - len(scene.self_pairs) + k)
                  for k, (la, lb) in enumerate(scene.self_pairs) for a in range(n_links)
                  for b in range(n_links) if (owner[a], owner[b]) == (la, lb)]  # fmt: skip
        moves = {s for s, _ in moving_parts}
        moving = [pair for pair in pairs if joints[pair[0]] != 0 or joints[pair[1]] != 0
                  or pair[1] in moves]  # fmt: skip
        index = {pair: k for k, pair in enumerate(pairs)}
        fixed = [pair for pair in pairs if pair not in moving]
        placements = model.jointPlacements
        ee_frame = model.frames[scene.robot.ee_frame_id]
        chain = Chain(
            parents=np.array(model.parents, dtype=np.int64),
            joint_rot=np.array([placements[j].rotation for j in range(model.njoints)]),
            joint_p=np.array([placements[j].translation for j in range(model.njoints)]),
            axes=axes,
            q_index=np.array(model.idx_qs, dtype=np.int64),
            ee_joint=int(ee_frame.parentJoint),
            ee_p=np.array(ee_frame.placement.translation),
            ee_rot=np.array(ee_frame.placement.rotation),
        )
        shape_arrays = Shapes(
            vertices=np.concatenate([c[0] for c in cores] or [np.zeros((0, 3))]),
            starts=starts,
            neighbours=neighbours,
            offsets=offsets,
            extents=np.array([np.max(np.linalg.norm(c[0], axis=1)) for c in cores]),
            radii=np.array([c[1] for c in cores], dtype=float),
            joint=np.array(joints, dtype=np.int64),
            rot=np.array([T[:3, :3] for T in poses]).reshape(-1, 3, 3),
            p=np.array([T[:3, 3] for T in poses]).reshape(-1, 3),
            capsule_a=np.array([b[0] for b in bounds]).reshape(-1, 3),
            capsule_b=np.array([b[1] for b in bounds]).reshape(-1, 3),
            capsule_r=np.array([b[2] for b in bounds], dtype=float),
        )
        reach = _reach(placements, poses[:n_links], cores[:n_links])
        out = cls(chain, shape_arrays, _pair_rows(moving, index), len(pairs), cell_count, reach,
                  tuple(moving_parts))  # fmt: skip
        if fixed:
            inputs = out.inputs(_pair_rows(fixed, index))
            static = _evaluate(np.zeros(model.nq), inputs, np.full(2, np.inf))
            out.static_min = np.array(static[:2])
        return out

    def at(self, t: float) -> None:
        """Put the moving obstacles' shapes at their poses of time t [s] (in place), and lower
        the remembered bounds of their pairs by how far each moved.

        Args:
            t: time [s].
        """
        for shape, obstacle in self.moving_parts:
            _place(shape, obstacle.pose_at(t), self.inputs())

    def evaluate(
        self, q: np.ndarray, obstacles: bool = True, self_pairs: bool = True
    ) -> tuple[float, float, np.ndarray, np.ndarray]:
        """(obstacle clearance [m], self clearance [m], end-effector position [m] and rotation
        (3×3, world)) at q [rad]; a clearance is 0 on overlap and +inf without pairs of its
        kind or when not asked for (both False: kinematics only).

        Args:
            q: joint angles, shape (nq,) [rad].
            obstacles: whether to measure the link-obstacle clearance.
            self_pairs: whether to measure the clearance of the checked link pairs.

        Returns:
            (obstacle clearance [m], self clearance [m], end-effector position, shape (3,) [m],
            end-effector rotation, shape (3, 3)).
        """
        pairs, static_min = self.select(obstacles, self_pairs)
        return _evaluate(q, self.inputs(pairs), static_min)

    def select(self, obstacles: bool, self_pairs: bool) -> tuple[np.ndarray, np.ndarray]:
        """(pairs, static_min) of the kinds asked for; the others count as +inf (read-only:
        the same arrays every call).

        Args:
            obstacles: whether to keep the link-obstacle pairs.
            self_pairs: whether to keep the checked link pairs.

        Returns:
            (the rows of `pairs` of those kinds, static_min with +inf for the others [m]).
        """
        kinds = (bool(obstacles), bool(self_pairs))
        if kinds not in self._selected:
            keep = np.array(kinds)
            self._selected[kinds] = (self.pairs[keep[self.pairs[:, 3]]],
                                     np.where(keep, self.static_min, np.inf))  # fmt: skip
        return self._selected[kinds]

    def near_pairs(
        self,
        pairs: np.ndarray,
        box: tuple[np.ndarray, np.ndarray],
        sweep: np.ndarray | None = None,
    ) -> np.ndarray:
        """The rows of `pairs` that can hold the smallest link-obstacle distance anywhere in
        `box` (lower, upper joint angles [rad]); link pairs are all kept.

        A shape point moves at most δ = Σ_j sweep_j |Δq_j| from the box's centre c (sweep_j
        = reach without a per-joint bound), so over the box a pair stays above its lower
        bound at c less δ, and the smallest distance stays below the smallest upper bound at
        c plus δ: a pair whose lower bound exceeds that by 2δ can never be the minimum (nor
        reach GJK in `_evaluate`'s broad phase).

        Args:
            pairs: pair rows, as in `pairs`, shape (k, 5).
            box: (lower, upper) joint angles, each shape (nq,) [rad].
            sweep: per joint, how far a shape point moves at most per unit of its motion,
                shape (nq,) [m/rad] (robots.sweep.joint_sweep); None: `reach` for each.

        Returns:
            The rows kept, shape (k', 5).
        """
        lower, upper = box
        weights = np.full(lower.size, self.reach) if sweep is None else sweep
        return _near_pairs(lower, upper, weights, self.static_min[OBSTACLE],
                           self.inputs(pairs))  # fmt: skip

    def inputs(self, pairs: np.ndarray | None = None) -> tuple:
        """What the compiled evaluation reads, after q and before static_min.

        Args:
            pairs: the pair rows to evaluate, shape (k, 5); None for all of `pairs`.

        Returns:
            ClearanceInputs (chain, shapes, scratch, pair rows) packed, as kernels take it
            from Python (compiled_bundles.packed).
        """
        return (*self._packed, self.pairs if pairs is None else pairs)


@jit()
def _place(shape, T, packed_inputs):
    """Put an obstacle's shape at pose T (4×4, world), lowering the remembered bound of each
    of its pairs by how far it moved."""
    inputs = named_inputs(packed_inputs)
    shapes, memory, pairs = inputs.shapes, inputs.scratch.memory, inputs.pairs
    R, p = np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3])
    before = np.concatenate((shapes.rot[shape].ravel(), shapes.p[shape])).reshape(1, 12)
    moved = _moved(before, 0, 0, R.reshape(1, 3, 3), p.reshape(1, 3), 0, shapes.extents[shape])
    if moved > 0.0:
        for k in range(pairs.shape[0]):
            if pairs[k, 1] == shape:
                memory[pairs[k, 2], 0] -= moved
        shapes.rot[shape] = R
        shapes.p[shape] = p


@jit()
def _evaluate(q, packed_inputs, static_min):
    """(obstacle clearance, self clearance, end-effector position, end-effector rotation):
    forward kinematics, shape poses, lower bounds, then exact GJK in order of bound, skipping
    a pair whose bound is not below the best distance of its kind (the broad phase of Scene).

    A pair's bound is its last bound (`memory`: an exact distance, or a capsule gap that ruled
    it out) less how far each shape has moved since: a search evaluates nearby
    configurations, so a far pair is measured once, not at every evaluation. Its capsules'
    gap is taken only when that is not enough, and remembered when it rules the pair out."""
    inputs = named_inputs(packed_inputs)
    chain, shapes, pairs = inputs.chain, inputs.shapes, inputs.pairs
    memory, simplices = inputs.scratch.memory, inputs.scratch.simplices
    oR, op = _joint_poses(q, chain)
    ee, ee_R = _ee_pose(oR, op, chain)
    world_R, world_p, ends = _shape_poses(oR, op, shapes, pairs, False)
    npairs = pairs.shape[0]
    lower = np.empty(npairs)
    has_obstacle = has_self = False  # a kind without pairs here cannot improve
    for k in range(npairs):
        a, b = pairs[k, 0], pairs[k, 1]
        lower[k] = _remembered_bound(
            memory, pairs[k, 2], a, b, world_R, world_p, shapes.extents, shapes.joint
        )
        if pairs[k, 3] == 1:
            has_self = True
        else:
            has_obstacle = True
    # Scalars, not a 2-array: this runs three times per BAORNN iteration.
    best_obstacle, best_self = static_min[0], static_min[1]
    for _ in range(npairs):
        k = np.argmin(lower)  # in order of bound: few pairs are taken, a sort costs more
        bound = lower[k]
        lower[k] = np.inf
        limit = -np.inf
        if has_obstacle:
            limit = best_obstacle
        if has_self and best_self > limit:
            limit = best_self
        if bound >= limit:
            break  # no later pair can lower either minimum
        self_pair = pairs[k, 3] == 1
        best = best_self if self_pair else best_obstacle
        if bound >= best:
            continue
        a, b = pairs[k, 0], pairs[k, 1]
        row = memory[pairs[k, 2]]
        _place_ends(a, world_R, world_p, shapes.capsule_a, shapes.capsule_b, ends)
        _place_ends(b, world_R, world_p, shapes.capsule_a, shapes.capsule_b, ends)
        gap = _segment_distance(ends[a, 0], ends[a, 1], ends[b, 0], ends[b, 1])
        gap -= shapes.capsule_r[a] + shapes.capsule_r[b]
        if gap >= best:
            if gap > bound:
                _remember(row, gap, world_R[a], world_p[a], world_R[b], world_p[b])
            continue
        radii = shapes.radii
        d = gjk_distance(shapes.vertices, shapes.neighbours, shapes.offsets, inputs.scratch.hints,
                         a, world_R[a], world_p[a], radii[a],
                         b, world_R[b], world_p[b], radii[b], simplices[pairs[k, 2]])  # fmt: skip
        _remember(row, d, world_R[a], world_p[a], world_R[b], world_p[b])
        if self_pair and d < best_self:
            best_self = d
        elif not self_pair and d < best_obstacle:
            best_obstacle = d
    return best_obstacle, best_self, ee, ee_R
