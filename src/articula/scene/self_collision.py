"""Which link pairs a self-collision check must look at: an allowed-collision matrix.

Built the way MoveIt's setup assistant builds its matrix: a pair is skipped when its links are
adjacent in the kinematic tree (they touch at their joint by design), when over random
configurations within the joint limits it never comes closer than a margin (it cannot collide)
or always overlaps (their hulls overlap whatever the joints do, so a check would only ever
say "colliding"), or when the scene file allows it. Every other pair is checked.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from articula.robots.model import RobotModel
from articula.scene.pairs import link_pairs
from articula.scene.scene import Scene

Reason = Literal["adjacent", "never close", "always touching", "allowed"]
SAMPLES = 1000  # random configurations; MoveIt's assistant defaults to 10,000 collision checks
MARGIN = 0.02  # [m] a pair that never comes closer than this over the samples is skipped


@dataclass(frozen=True)
class SelfCollisionMatrix:
    """The link pairs to check, and each skipped pair with why it was skipped.

    Attributes:
        checked: the link pairs (a, b) by name whose distance a self-collision check takes.
        skipped: every other pair, with its reason: "adjacent", "never close",
            "always touching" or "allowed".
    """

    checked: tuple[tuple[str, str], ...]
    skipped: dict[tuple[str, str], Reason]


def self_collision_matrix(
    robot: RobotModel,
    allow_pairs: Sequence[Sequence[str]] = (),
    samples: int = SAMPLES,
    margin: float = MARGIN,
    seed: int = 0,
) -> SelfCollisionMatrix:
    """The allowed-collision matrix of `robot`.

    Args:
        robot: the arm; pairs are between its links with collision shapes.
        allow_pairs: [a, b] link name pairs never to check (a gripper's fingers, say).
        samples: random configurations, uniform within the joint limits.
        margin: [m] a pair never closer than this over the samples is skipped.
        seed: seeds the samples (the matrix is a property of the robot: keep it fixed).

    Returns:
        The pairs to check, in link order, and the skipped ones with their reason.
    """
    names = [link.name for link in robot.links]
    skipped: dict[tuple[str, str], Reason] = {
        (names[a], names[b]): "allowed" for a, b in link_pairs(allow_pairs, names, "allow_pairs")
    }
    joint = {link.name: robot.model.frames[link.frame_id].parentJoint for link in robot.links}
    parents = robot.model.parents
    candidates = []
    for a, b in itertools.combinations(names, 2):
        if (a, b) in skipped:
            continue
        ja, jb = joint[a], joint[b]
        if ja == jb or parents[ja] == jb or parents[jb] == ja:
            skipped[a, b] = "adjacent"
        else:
            candidates.append((a, b))
    if candidates:
        scene = Scene(robot, [], self_pairs=candidates)
        rng = np.random.default_rng(seed)
        Q = rng.uniform(robot.lower, robot.upper, (samples, robot.nq))
        D = np.array([scene.self_distances(q) for q in Q])
        for k, pair in enumerate(scene.self_pair_names):
            if D[:, k].min() > margin:
                skipped[pair] = "never close"
            elif D[:, k].max() <= 0.0:
                skipped[pair] = "always touching"
    checked = tuple(pair for pair in itertools.combinations(names, 2) if pair not in skipped)
    return SelfCollisionMatrix(checked, skipped)
