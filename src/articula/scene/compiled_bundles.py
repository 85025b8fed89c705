"""The named bundles the compiled distance kernels take: the kinematic chain, the shapes and
the search's scratch, each a NamedTuple of arrays (numba passes one as a typed record, so a
kernel names `chain.parents` instead of taking 24 arrays in a row).

`Chain` never changes after it is built; `Shapes` changes only where a moving obstacle is put
at a new pose (`rot`, `p`, in place); `Scratch` is the evaluations' memory and
changes at every call.

A bundle crosses from Python into a kernel as plain nested tuples (`packed`), and the kernel
names it again at its top (`named_inputs`, `Problem(*problem)`): numba's dispatcher types a
NamedTuple argument more than twice as slowly as a plain tuple of the same arrays
(benchmarks/bundle_dispatch.py on the iiwa14 scene: 3.6 µs against 1.5 µs per call, the
difference a quarter of an evaluation), while naming it inside a kernel costs nothing.
Calls between kernels pass the named form; a helper that takes a bundle and runs at every
evaluation is inlined (`jit(inline="always")`), and one that runs per pair takes only the
arrays it reads, since a call that is not inlined counts references twice for every array of
its arguments (together about a tenth of a BAORNN iteration, benchmarks/baornn.py).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from articula.numba_cache import jit


class Chain(NamedTuple):
    """A revolute kinematic chain and its end effector.

    Attributes:
        parents: Parent joint index of each joint, shape (joints,); joint 0 is the world.
        joint_rot: Rotation of each joint's placement in its parent joint frame, (joints, 3, 3).
        joint_p: Position of each joint's placement in its parent joint frame, (joints, 3) [m].
        axes: Revolute axis of each joint in its own frame, shape (joints, 3) (unit vectors).
        q_index: Index of each joint's angle in q, shape (joints,).
        ee_joint: The joint the end-effector frame moves with.
        ee_p: End-effector origin in its joint frame, shape (3,) [m].
        ee_rot: End-effector orientation in its joint frame, shape (3, 3).
    """

    parents: np.ndarray
    joint_rot: np.ndarray
    joint_p: np.ndarray
    axes: np.ndarray
    q_index: np.ndarray
    ee_joint: int
    ee_p: np.ndarray
    ee_rot: np.ndarray


class Shapes(NamedTuple):
    """Every link shape, then every obstacle part: convex cores and bounding capsules.

    Attributes:
        vertices: Core vertices of every shape in its own frame, concatenated, (total, 3) [m].
        starts: Where each shape's vertices start in `vertices`, shape (shapes + 1,).
        neighbours: Vertices joined by a hull edge, CSR by vertex (indices into `vertices`).
        offsets: CSR offsets of each vertex's neighbours, shape (total + 1,).
        extents: Largest |x| of a core vertex in its shape's frame, shape (shapes,) [m].
        radii: Radius swept around each core (sphere, capsule; 0 for a polytope), (shapes,) [m].
        joint: The joint each shape moves with, shape (shapes,) (0: the world).
        rot: Rotation of each shape in its joint frame (world for obstacles), (shapes, 3, 3).
        p: Position of each shape in its joint frame (world for obstacles), (shapes, 3) [m].
        capsule_a: First end of each bounding capsule's segment, shape frame, (shapes, 3) [m].
        capsule_b: Second end of each bounding capsule's segment, shape frame, (shapes, 3) [m].
        capsule_r: Radius of each bounding capsule, shape (shapes,) [m].
    """

    vertices: np.ndarray
    starts: np.ndarray
    neighbours: np.ndarray
    offsets: np.ndarray
    extents: np.ndarray
    radii: np.ndarray
    joint: np.ndarray
    rot: np.ndarray
    p: np.ndarray
    capsule_a: np.ndarray
    capsule_b: np.ndarray
    capsule_r: np.ndarray


class Scratch(NamedTuple):
    """What the evaluations remember between calls (written in place by every call).

    Attributes:
        hints: Vertex each shape's support search starts from, shape (shapes,).
        simplices: Each pair's GJK warm start (gjk.py), shape (pairs, 7).
        memory: Each pair's last lower bound [m] and the two shapes' poses (R, p) then, shape
            (pairs, 25) (bound −inf: none yet).
    """

    hints: np.ndarray
    simplices: np.ndarray
    memory: np.ndarray

    @classmethod
    def fresh(cls, starts: np.ndarray, pairs: int) -> Scratch:
        """Scratch that remembers nothing yet.

        Args:
            starts: Where each shape's vertices start (Shapes.starts), shape (shapes + 1,).
            pairs: How many pairs there are.

        Returns:
            The scratch arrays.
        """
        return cls(
            starts[:-1].copy(),
            np.zeros((pairs, 7), dtype=np.int64),
            np.full((pairs, 25), -np.inf),
        )


class ClearanceInputs(NamedTuple):
    """What one compiled clearance evaluation reads (CompiledClearance.inputs).

    Attributes:
        chain: The kinematic chain.
        shapes: The link shapes and obstacle parts.
        scratch: The evaluations' memory, written in place.
        pairs: Rows (shape a, shape b, scratch row, OBSTACLE | SELF, cell) of the pairs that
            count, shape (pairs, 5).
    """

    chain: Chain
    shapes: Shapes
    scratch: Scratch
    pairs: np.ndarray


def packed(bundle: tuple) -> tuple:
    """A bundle as plain nested tuples, the form kernels take from Python (the same arrays,
    not copies: a kernel's writes reach the bundle's arrays).

    Args:
        bundle: a NamedTuple of arrays, numbers and bundles.

    Returns:
        The same fields in order, nested bundles packed likewise.
    """
    return tuple(packed(field) if isinstance(field, tuple) else field for field in bundle)


@jit(inline="always")
def named_inputs(inputs):
    """ClearanceInputs from its packed form (inlined into each kernel that takes it).

    Args:
        inputs: the packed form (CompiledClearance.inputs): chain, shapes, scratch, pairs.

    Returns:
        The same arrays as a ClearanceInputs.
    """
    chain, shapes, scratch, pairs = inputs
    return ClearanceInputs(Chain(*chain), Shapes(*shapes), Scratch(*scratch), pairs)
