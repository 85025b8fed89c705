"""track(): run a planner along a reference path over time, recording what a user plots."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError, InfeasibleError
from articula.planning.baornn import Baornn

Trajectory = Callable[[float], np.ndarray]


@dataclass(frozen=True)
class PlanResult:
    """Time series of a tracking run: t [s], q [rad], x and x_ref [m], error and clearance [m]."""

    t: np.ndarray
    q: np.ndarray
    x: np.ndarray
    x_ref: np.ndarray
    error: np.ndarray
    clearance: np.ndarray


def track(
    planner: Baornn, trajectory: Trajectory, q0: np.ndarray, dt: float, duration: float
) -> PlanResult:
    """Follow `trajectory` from q0 [rad] for `duration` [s], one planner step per `dt` [s]."""
    if not (np.isfinite(dt) and dt > 0 and np.isfinite(duration) and duration >= dt):
        raise ConfigError("planner.dt/duration", f"need 0 < dt <= duration (got {dt}, {duration})")
    objective = planner.objective
    scene, robot = objective.scene, objective.scene.robot
    q = robot.check_q(q0, "robot.q0").copy()
    if np.any(q < robot.lower) or np.any(q > robot.upper):
        raise InfeasibleError("robot.q0: the start breaks the joint limits (Eq. 1.9)")
    if scene.obstacles and scene.min_distance(q) <= objective.d_min:
        raise InfeasibleError(
            f"robot.q0: the start is within d_min = {objective.d_min} m of an obstacle (Eq. 1.12)"
        )
    steps = round(duration / dt)
    t = np.arange(steps) * dt
    qs = np.empty((steps, q.size))
    x = np.empty((steps, 3))
    x_ref = np.empty((steps, 3))
    clearance = np.full(steps, np.inf)
    for n, tn in enumerate(t):
        x_ref[n] = trajectory(tn)
        q, _ = planner.step(q, x_ref[n], tn)
        qs[n] = q
        x[n] = robot.ee_position(q)
        if scene.obstacles:
            clearance[n] = scene.min_distance(q, tn)
    error = np.linalg.norm(x - x_ref, axis=1)
    return PlanResult(t, qs, x, x_ref, error, clearance)
