"""Clearance along a motion sampled finer than its plan (the servo stream's samples, the twin's
measured joints at every tick): the smallest obstacle and self clearances with the pair and
time of each, and the line a run fails with when one falls below its floor (planner.d_min,
robot.self_d_min) by more than a stated tolerance.

The planners keep the floors at each control period's set-point only. Between two set-points
the stream is a cubic B-spline of them, which cuts the corners of the set-points' polygon, so
it may pass a little closer than either set-point; a measured arm lags its stream besides.
The tolerances below bound what that may cost, measured on the real-arm scenes
(docs/guides/servo.md, "Clearance between set-points").
"""

from __future__ import annotations

from typing import Any

import numpy as np

from articula.scene.scene import Scene

__all__ = ["PLANT_TOLERANCE", "STREAM_TOLERANCE", "clearance_failure", "sampled_clearance"]

STREAM_TOLERANCE = 0.5e-3  # [m] the stream may pass this much closer than a floor
PLANT_TOLERANCE = 1e-3  # [m] the twin's measured arm may pass this much closer than a floor

_KINDS = (("min_clearance", "planner.d_min"), ("min_self_clearance", "robot.self_d_min"))


def sampled_clearance(scene: Scene, q: np.ndarray, t: np.ndarray, prefix: str) -> dict[str, Any]:
    """The smallest clearances over every sample of a motion, and where they were.

    Args:
        scene: the robot, its obstacles and its checked link pairs.
        q: joint positions of each sample, shape (m, n) [rad].
        t: time of each sample, placing moving obstacles, shape (m,) [s].
        prefix: the metrics' prefix ("stream", "plant").

    Returns:
        {prefix}_min_clearance (smallest link-obstacle distance [m]; None: no obstacle),
        {prefix}_min_self_clearance (smallest distance of a checked link pair [m]; None: no
        pair), each with its _pair ("link / obstacle" or "link / link") and _at (the sample's
        time [s]).
    """
    q, t = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
    d = np.array([scene.clearances(qk, float(tk)) for qk, tk in zip(q, t, strict=True)])
    metrics: dict[str, Any] = {}
    for column, (name, _) in enumerate(_KINDS):
        k = int(np.argmin(d[:, column]))
        value = float(d[k, column])
        pair = None
        if np.isfinite(value) and column == 0:
            near = scene.distances(q[k], float(t[k]))
            i, j = np.unravel_index(int(np.argmin(near)), near.shape)
            pair = f"{scene.link_names[i]} / {scene.obstacles[j].name}"
        elif np.isfinite(value):
            a, b = scene.self_pair_names[int(np.argmin(scene.self_distances(q[k])))]
            pair = f"{a} / {b}"
        metrics[f"{prefix}_{name}"] = value if np.isfinite(value) else None
        metrics[f"{prefix}_{name}_pair"] = pair
        metrics[f"{prefix}_{name}_at"] = float(t[k]) if pair is not None else None
    return metrics


def clearance_failure(
    metrics: dict[str, Any],
    prefix: str,
    what: str,
    floors: tuple[float, float],
    tolerance: float,
) -> str | None:
    """Why a sampled motion failed its clearance, or None when it kept it.

    Args:
        metrics: the motion's metrics, with those of sampled_clearance under `prefix`.
        prefix: the metrics' prefix ("stream", "plant").
        what: the motion, as the line names it ("the servo stream").
        floors: (planner.d_min, robot.self_d_min) [m].
        tolerance: how far below a floor the motion may pass [m].

    Returns:
        One line naming the pair, its distance, the floor and when; None: no floor broken,
        or the plan itself collides (`collisions`, `self_collisions`: that exits 4).
    """
    if metrics.get("collisions") or metrics.get("self_collisions"):
        return None
    for (name, key), floor in zip(_KINDS, floors, strict=True):
        value = metrics.get(f"{prefix}_{name}")
        if value is not None and value < floor - tolerance:
            return (
                f"{what} passed {1e3 * value:.2f} mm from {metrics[f'{prefix}_{name}_pair']} "
                f"at t = {metrics[f'{prefix}_{name}_at']:.3f} s, below {key} = {1e3 * floor:g} mm "
                f"by more than the {1e3 * tolerance:g} mm tolerance"
            )
    return None
