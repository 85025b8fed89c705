"""What `track` needs from a planner: its scene, its hard clearance, and one control step."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from articula.planning.task import Target, Task
from articula.scene.scene import Scene

WARM_UP_STEPS = 3  # steps a warm-up takes: the first compiles, the next let Python specialise


class Planner(Protocol):
    """One control period at a time: from q [rad] toward the target."""

    @property
    def scene(self) -> Scene:
        """The robot and obstacles the planner plans in."""
        ...

    @property
    def d_min(self) -> float:
        """Hard minimum clearance [m] the start must respect (Eq. 1.12)."""
        ...

    @property
    def task(self) -> Task:
        """What the end effector tracks: position, pose or position and tool axis."""
        ...

    @property
    def iterations(self) -> int:
        """Inner iterations (BAORNN) or solver calls (baselines) done so far."""
        ...

    @property
    def infeasible(self) -> int:
        """Periods whose step could not keep every constraint (it braked, or ended closer
        than d_min or self_d_min) or whose limits could not all hold."""
        ...

    def step(self, q: np.ndarray, target: Target, t: float) -> np.ndarray:
        """The configuration [rad] for time t [s].

        Args:
            q: joint angles at the start of the period, shape (nq,) [rad].
            target: the period's target.
            t: time of the period, placing moving obstacles [s].

        Returns:
            The joint angles for time t, shape (nq,) [rad].
        """
        ...

    def reset(self) -> None:
        """Forget the previous periods (their motion, their reference): a new start at rest."""
        ...

    def follow(self, motion: np.ndarray) -> None:
        """Take the arm's measured joint motion over the period that ended as its motion.

        Args:
            motion: the measured joint displacement over that period, shape (nq,) [rad].
        """
        ...

    def warm_up(self, q: np.ndarray, target: Target) -> None:
        """Compile (or load from numba's cache) every kernel a step runs, leaving no trace: the
        same counts, random state and memory as before.

        Args:
            q: a configuration to step from, shape (nq,) [rad].
            target: a target to step toward.
        """
        ...
