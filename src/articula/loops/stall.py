"""A stalled run says so: how long the arm stood still off its path, the pair or joint limit it
stood at, and, for a run that did not track, the cause measured instead of guessed."""

from __future__ import annotations

from typing import Any

import numpy as np

from articula.loops.tracking import PlanResult
from articula.robots.model import RobotModel
from articula.scene.scene import Scene

STALL_SPEED = 0.01  # a stalled arm moves slower than this fraction of every speed limit
STALL_ERROR = 1e-3  # [m] the tool error above which standing still is a stall (or tolerance)
STALL_SHARE = 0.25  # a run off its path that stood still this share of that time stalled
BOUNDARY_BAND = 2e-3  # [m] a stall this close to its floor is a stall at that boundary
LIMIT_BAND = 1e-3  # [rad] a joint this close to a position limit is at it


def stall_metrics(
    run: PlanResult, scene: Scene, tolerance: float, d_min: float
) -> dict[str, float | str | None]:
    """How long the run stalled and where: stalled_s, the time [s] whose tool error was above
    min(tolerance, STALL_ERROR) while every joint moved slower than STALL_SPEED of its speed
    limit (joints without one do not count), and off_path_s, the time above that error
    whether moving or not; at the first period of the longest stall,
    stall_at [s], stall_error [m], the closest pair there (stall_pair, "link / obstacle" or
    "link / link"), its distance stall_clearance [m] and how far above its floor it was
    (stall_margin [m]), and stall_joint_limit, the joints at a position limit ("" for none);
    and, at the largest error (worst_at [s]), the pair closest to its floor (worst_pair,
    worst_clearance [m], worst_margin [m]).

    Args:
        run: the tracking run.
        scene: its robot, obstacles and checked link pairs.
        tolerance: the rms error above which the path counts as not tracked [m].
        d_min: the hard clearance from obstacles [m] (self pairs: the scene's self_d_min).

    Returns:
        The metrics above; the stall_* ones None when the run never stalled.
    """
    robot = scene.robot
    dt = float(run.t[1] - run.t[0]) if len(run.t) > 1 else 1.0
    off = run.error > min(tolerance, STALL_ERROR)
    stalled = off & standing_still(robot, run.q, run.q0, dt)
    out: dict[str, float | str | None] = {
        "stalled_s": float(np.sum(stalled)) * dt,
        "off_path_s": float(np.sum(off)) * dt,
    }
    worst = int(np.argmax(run.error))
    pair, distance, floor = closest_pair(scene, run.q[worst], float(run.t[worst]), d_min)
    out |= {
        "worst_at": float(run.t[worst]),
        "worst_pair": pair,
        "worst_clearance": distance,
        "worst_margin": None if distance is None else distance - floor,
    }
    keys = ("stall_at", "stall_error", "stall_pair", "stall_clearance", "stall_margin")
    out |= dict.fromkeys(keys) | {"stall_joint_limit": None}
    if not np.any(stalled):
        return out
    k = _longest_stretch(stalled)
    pair, distance, floor = closest_pair(scene, run.q[k], float(run.t[k]), d_min)
    at_limit = (run.q[k] - robot.lower < LIMIT_BAND) | (robot.upper - run.q[k] < LIMIT_BAND)
    return out | {
        "stall_at": float(run.t[k]),
        "stall_error": float(run.error[k]),
        "stall_pair": pair,
        "stall_clearance": distance,
        "stall_margin": None if distance is None else distance - floor,
        "stall_joint_limit": ", ".join(np.asarray(robot.joint_names)[at_limit]),
    }


def standing_still(
    robot: RobotModel, q: np.ndarray, q0: np.ndarray | None, dt: float
) -> np.ndarray:
    """Which periods moved every joint slower than STALL_SPEED of its speed limit (joints
    without one do not count; a continuous joint the short way round).

    Args:
        robot: the robot, for its speed limits.
        q: the commanded joints of each period, shape (k, nq) [rad].
        q0: the start, shape (nq,) [rad]; None: the first period counts as moving.
        dt: the control period [s].

    Returns:
        One flag per period, shape (k,).
    """
    before = np.vstack([q[:1] if q0 is None else q0, q[:-1]])
    limit = np.where(robot.velocity_limit > 0, robot.velocity_limit, np.inf)
    speed = np.abs(robot.difference(q, before)) / dt / limit
    still = np.max(speed, axis=1, initial=0.0) < STALL_SPEED
    if q0 is None and len(still):
        still[0] = False
    return still


def closest_pair(
    scene: Scene, q: np.ndarray, t: float, d_min: float
) -> tuple[str | None, float | None, float]:
    """(the pair nearest its floor at q, "link / obstacle" or "link / link"; its distance [m];
    its floor, d_min or the scene's self_d_min [m]); (None, None, 0) without pairs.

    Args:
        scene: the robot, its obstacles and its checked link pairs.
        q: joint angles, shape (nq,) [rad].
        t: time, placing moving obstacles [s].
        d_min: the hard clearance from obstacles [m].

    Returns:
        The pair's name, its distance [m] and its floor [m].
    """
    links = scene.link_names
    candidates: list[tuple[float, str, float]] = []
    if scene.obstacles:
        d = scene.distances(q, t)
        i, j = np.unravel_index(int(np.argmin(d)), d.shape)
        name = f"{links[i]} / {scene.obstacles[j].name}"
        candidates.append((float(d[i, j]) - d_min, name, d_min))
    if scene.self_pairs:
        d = scene.self_distances(q)
        k = int(np.argmin(d))
        a, b = scene.self_pair_names[k]
        candidates.append((float(d[k]) - scene.self_d_min, f"{a} / {b}", scene.self_d_min))
    if not candidates:
        return None, None, 0.0
    margin, name, floor = min(candidates)
    return name, margin + floor, floor


def not_tracked_cause(metrics: dict[str, Any], infeasible: float, periods: int) -> str:
    """The measured reason a run did not track, in words: an error that stayed under a
    millimetre (a tolerance tighter than the method tracks), a stall at a clearance boundary
    or a joint limit (naming the pair or joint and the distance), a start no step could leave,
    or an arm that moved but stayed off the path (naming the pair nearest its floor at the
    largest error).

    Args:
        metrics: the run's tracking and stall metrics (stall_metrics).
        infeasible: the periods that could not keep every constraint.
        periods: the run's periods.

    Returns:
        One clause, starting in lower case.
    """
    stalled = metrics.get("stalled_s") or 0.0
    if metrics["max_error"] < STALL_ERROR:
        return (
            f"the error stayed within {1e3 * metrics['max_error']:.3g} mm: the tolerance is "
            "tighter than the method tracks"
        )
    if stalled <= STALL_SHARE * (metrics.get("off_path_s") or 0.0):
        worst = metrics.get("worst_pair")
        near = (
            ""
            if worst is None
            else f"; at the largest error, t = {metrics['worst_at']:.2f} s, {worst} was "
            f"{1e3 * metrics['worst_clearance']:.2f} mm apart ({1e3 * metrics['worst_margin']:.2f}"
            " mm above its floor)"
        )
        return (
            f"the arm moved but stayed off the path (max {1e3 * metrics['max_error']:.1f} mm, "
            f"{metrics.get('off_path_s') or 0.0:.2f} s off it, {stalled:.2f} s of that standing "
            f"still; {int(infeasible)} of {periods} periods could not keep every constraint"
            f"{near})"
        )
    where = f"for {stalled:.2f} s from t = {metrics['stall_at']:.2f} s"
    margin = metrics.get("stall_margin")
    if margin is not None and margin < BOUNDARY_BAND:
        return (
            f"the arm stalled {where} at a clearance boundary: {metrics['stall_pair']} at "
            f"{1e3 * metrics['stall_clearance']:.2f} mm ({1e3 * margin:.2f} mm above its floor)"
        )
    if metrics.get("stall_joint_limit"):
        return f"the arm stalled {where} at the limit of {metrics['stall_joint_limit']}"
    if metrics["stall_at"] == 0.0 and infeasible >= 0.9 * periods:
        return (
            f"no step could leave the start: {int(infeasible)} of {periods} periods infeasible "
            f"(closest {metrics['stall_pair']} at {1e3 * metrics['stall_clearance']:.2f} mm)"
        )
    closest = (
        ""
        if metrics.get("stall_pair") is None
        else f"; closest {metrics['stall_pair']} at {1e3 * metrics['stall_clearance']:.2f} mm"
    )
    return (
        f"the arm stalled {where} {1e3 * metrics['stall_error']:.1f} mm off the path, away from "
        f"every boundary (a minimum of the method's objective{closest})"
    )


def _longest_stretch(flags: np.ndarray) -> int:
    """The first index of the longest run of True in `flags` (which has one)."""
    padded = np.concatenate([[False], flags, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    starts, ends = edges[::2], edges[1::2]
    return int(starts[np.argmax(ends - starts)])
