"""track(): run a planner along a reference path over time, recording what a user plots."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError, InfeasibleError
from articula.planning.planner import Planner

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
    planner_seconds: float  # time spent in planner.step alone [s], not in the recording


def track(
    planner: Planner, trajectory: Trajectory, q0: np.ndarray, dt: float, duration: float
) -> PlanResult:
    """Follow `trajectory` from q0 [rad] for `duration` [s], one planner step per `dt` [s]."""
    if not (np.isfinite(dt) and dt > 0 and np.isfinite(duration) and duration >= dt):
        raise ConfigError("planner.dt/duration", f"need 0 < dt <= duration (got {dt}, {duration})")
    scene, robot = planner.scene, planner.scene.robot
    q = robot.check_q(q0, "robot.q0").copy()
    if np.any(q < robot.lower) or np.any(q > robot.upper):
        raise InfeasibleError("robot.q0: the start breaks the joint limits (Eq. 1.9)")
    if scene.obstacles:
        d0 = scene.min_distance(q)
        if d0 <= 0:
            raise InfeasibleError(f"robot.q0: the start collides with an obstacle (d = {d0:.4f} m)")
        if d0 <= planner.d_min:
            raise InfeasibleError(
                f"robot.q0: the start is {d0:.4f} m from an obstacle, within d_min = "
                f"{planner.d_min} m (Eq. 1.12); lower d_min or move the start"
            )
    steps = round(duration / dt)
    t = np.arange(steps) * dt
    qs = np.empty((steps, q.size))
    x = np.empty((steps, 3))
    x_ref = np.empty((steps, 3))
    clearance = np.full(steps, np.inf)
    planner_seconds = 0.0
    for n, tn in enumerate(t):
        x_ref[n] = trajectory(tn)
        start = time.perf_counter()
        q = planner.step(q, x_ref[n], tn)
        planner_seconds += time.perf_counter() - start
        qs[n] = q
        x[n] = robot.ee_position(q)
        if scene.obstacles:
            clearance[n] = scene.min_distance(q, tn)
    error = np.linalg.norm(x - x_ref, axis=1)
    return PlanResult(t, qs, x, x_ref, error, clearance, planner_seconds)
