"""BAORNN (Algorithm 1): beetle-antennae search over joint angles, one time-step at a time."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from articula.errors import ConfigError
from articula.planning import baornn_kernel as kernel
from articula.planning.objective import Objective
from articula.scene.scene import Scene


@dataclass(frozen=True)
class BaornnParams:
    """Antenna length λ_k = c1·√g_k (1.23) [rad], c1 in rad/√m, and step δ_k = c2·λ_k (1.24),
    c2 dimensionless; iterations per control period."""

    c1: float = 0.5
    c2: float = 0.5
    iterations_per_step: int = 10

    def __post_init__(self) -> None:
        check_step_constants(self.c1, self.c2, self.iterations_per_step)


def check_step_constants(c1: float, c2: float, iterations_per_step: int) -> None:
    """ConfigError unless c1, c2 are finite and > 0 and there is at least one iteration."""
    if not (np.isfinite(c1) and c1 > 0 and np.isfinite(c2) and c2 > 0):
        raise ConfigError("planner.c1/c2", f"must be finite and > 0 (got {c1}, {c2})")
    if iterations_per_step < 1:
        raise ConfigError("planner.iterations_per_step", "must be >= 1")


class OnObjective:
    """The Planner properties of a planner that searches an Objective."""

    objective: Objective

    @property
    def scene(self) -> Scene:
        """The scene of the objective."""
        return self.objective.scene

    @property
    def d_min(self) -> float:
        """The hard clearance [m] of the objective (Eq. 1.12)."""
        return self.objective.d_min


@dataclass
class Baornn(OnObjective):
    """The faithful algorithm of Sect. 1.3.1; all randomness from the injected generator."""

    objective: Objective
    params: BaornnParams
    rng: np.random.Generator
    evaluations: int = field(default=0, init=False)
    iterations: int = field(default=0, init=False)

    def iterate(
        self, q: np.ndarray, g: float, x_ref: np.ndarray, t: float
    ) -> tuple[np.ndarray, float]:
        """One iteration of Algorithm 1 from (q, g = g(q)); returns the accepted (q, g)."""
        obj = self.objective
        b = self.rng.standard_normal(q.size)
        if obj.compiled is not None:
            self.evaluations += 3
            self.iterations += 1
            return kernel.iterations(q, g, x_ref, b[None, :], self.params.c1, self.params.c2,
                                     *obj.kernel_arguments())  # fmt: skip
        b /= math.sqrt(b @ b)  # a normalised random direction
        lam = self.params.c1 * np.sqrt(g) if np.isfinite(g) else self.params.c1  # Eq. (1.23)
        # Eqs. (1.15)-(1.18): antennae, projected onto Ω, evaluated by "virtual robots".
        _, g_left = obj.project_and_value(q + lam * b, q, g, x_ref, t)
        _, g_right = obj.project_and_value(q - lam * b, q, g, x_ref, t)
        delta = self.params.c2 * lam  # Eq. (1.24)
        step = q - delta * np.sign(g_left - g_right) * b  # Eq. (1.19)
        q_new, g_new = obj.project_and_value(step, q, g, x_ref, t)  # Eq. (1.20)
        self.evaluations += 3
        self.iterations += 1
        if g_new < g:  # Eqs. (1.21)-(1.22): accept only an improvement
            return q_new, g_new
        return q, g

    def step(self, q: np.ndarray, x_ref: np.ndarray, t: float) -> np.ndarray:
        """One control period: re-evaluate g for the new reference, then iterate."""
        obj, k = self.objective, self.params.iterations_per_step
        g = obj.value(q, x_ref, t)
        if obj.compiled is not None:
            # The same draws as k calls of iterate: the Generator fills rows in order.
            directions = self.rng.standard_normal((k, q.size))
            self.evaluations += 3 * k
            self.iterations += k
            q, _ = kernel.iterations(q, g, x_ref, directions, self.params.c1, self.params.c2,
                                     *obj.kernel_arguments())  # fmt: skip
            return q
        for _ in range(k):
            q, g = self.iterate(q, g, x_ref, t)
        return q
