"""The objective of Eq. (1.13) and the projection onto the feasible set Ω, Eq. (1.17)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError
from articula.scene.scene import Scene


@dataclass(frozen=True)
class Objective:
    """g = ||x_r − f(θ)|| + Λ / (min_i d_i)^β, Eqs. (1.5), (1.7), (1.11), (1.14).

    lambda_weight is Λ, beta is β, d_min [m] the hard clearance of Eq. (1.12). With several
    obstacles, Eq. (1.14) takes the largest penalty, i.e. the smallest distance over all of
    them, which is what Scene.min_distance returns.
    """

    scene: Scene
    lambda_weight: float
    beta: float = 1.0
    d_min: float = 0.0

    def __post_init__(self) -> None:
        for name in ("lambda_weight", "beta", "d_min"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ConfigError(f"planner.{name}", f"must be finite and >= 0 (got {value})")

    @property
    def needs_distance(self) -> bool:
        """False when neither the penalty nor the hard bound uses the obstacles (Λ = d_min = 0)."""
        return bool(self.scene.obstacles) and (self.lambda_weight > 0 or self.d_min > 0)

    def value(self, q: np.ndarray, x_ref: np.ndarray, t: float = 0.0) -> float:
        """Objective g at configuration q [rad] for the reference point x_ref [m]."""
        self.scene.robot.forward(q)
        x = self.scene.robot.data.oMf[self.scene.robot.ee_frame_id].translation
        g = float(np.linalg.norm(x_ref - x))  # Eq. (1.5)
        if self.lambda_weight > 0 and self.scene.obstacles:
            d = self.scene.min_distance(q, t)
            # Eq. (1.7): inside an obstacle the penalty has no finite value.
            g += self.lambda_weight / d**self.beta if d > 0 else np.inf
        return g

    def project(self, q: np.ndarray, q_current: np.ndarray, t: float = 0.0) -> np.ndarray:
        """P_Ω of Eq. (1.17): clip to the joint limits (1.9); keep q_current if d < d_min."""
        robot = self.scene.robot
        clipped = np.minimum(
            np.maximum(q, robot.model.lowerPositionLimit), robot.model.upperPositionLimit
        )
        if (
            self.needs_distance
            and self.d_min > 0
            and self.scene.min_distance(clipped, t) < self.d_min
        ):
            return q_current
        return clipped
