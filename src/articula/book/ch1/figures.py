"""Chapter 1 figures: link paths among the obstacles, time series, and snapshots of the arm."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from scipy.spatial import ConvexHull

from articula.book.figures import save
from articula.geometry.poses import transform_points
from articula.scene.scene import Scene


def joint_points(scene: Scene, q: np.ndarray) -> np.ndarray:
    """World positions [m] of every joint origin and the end effector at q: (joints + 1, 3)."""
    robot = scene.robot
    robot.forward(q)
    points = [robot.data.oMi[j].translation.copy() for j in range(1, robot.model.njoints)]
    points.append(robot.data.oMf[robot.ee_frame_id].translation.copy())
    return np.array(points)


def paths(scene: Scene, trace: Mapping[str, np.ndarray], title: str, path: Path) -> None:
    """3-D paths of every joint and the end effector with the obstacles and the reference,
    beside a top view (Figs. 1.4-1.6, 1.8, 1.9, 1.11, 1.12)."""
    q = joint_matrix(trace)
    every = max(1, len(q) // 400)
    points = np.array([joint_points(scene, qi) for qi in q[::every]])  # (times, joints, 3)
    ref = np.column_stack([trace["x_ref"], trace["y_ref"], trace["z_ref"]])
    fig = plt.figure(figsize=(12, 5.5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    top = fig.add_subplot(1, 2, 2)
    _obstacles_3d(ax, scene)
    _obstacles_top(top, scene)
    colors = plt.cm.viridis(np.linspace(0, 1, points.shape[1]))
    for j in range(points.shape[1]):
        label = "end effector" if j == points.shape[1] - 1 else f"joint {j + 1}"
        ax.plot(*points[:, j].T, color=colors[j], lw=0.8, label=label)
        top.plot(points[:, j, 0], points[:, j, 1], color=colors[j], lw=0.8, label=label)
    ax.plot(*ref.T, "k--", lw=1.0, label="reference")
    top.plot(ref[:, 0], ref[:, 1], "k--", lw=1.0, label="reference")
    ax.plot(*points[-1].T, "o-", color="C3", lw=2, ms=3, label="arm at the end")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    _equal_3d(ax, np.vstack([points.reshape(-1, 3), ref]))
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.set_title("top view")
    top.set_aspect("equal")
    top.grid(True, alpha=0.3)
    top.legend(fontsize=7, loc="best")
    fig.suptitle(title)
    save(fig, path)


def time_series(trace: Mapping[str, np.ndarray], title: str, path: Path) -> None:
    """Task space, joint space, error, clearance, joint velocity and acceleration against t."""
    t = trace["t"]
    q = joint_matrix(trace)
    dt = float(t[1] - t[0])
    qd = np.gradient(q, dt, axis=0)
    qdd = np.gradient(qd, dt, axis=0)
    fig, axes = plt.subplots(3, 2, figsize=(12, 9), sharex=True)
    ax = axes[0, 0]
    for k, name in enumerate("xyz"):
        ax.plot(t, trace[name], color=f"C{k}", lw=1.0, label=name)
        ax.plot(t, trace[f"{name}_ref"], color=f"C{k}", ls="--", lw=0.8)
    ax.set_ylabel("end effector [m] (dashed: reference)")
    ax.legend(fontsize=7)
    _lines(axes[0, 1], t, q, "joint angle [rad]")
    ax = axes[1, 0]
    ax.semilogy(t, np.maximum(trace["error"], 1e-9), lw=0.8)
    ax.set_ylabel("tracking error [m]")
    ax = axes[1, 1]
    ax.plot(t, trace["clearance"], lw=0.8)
    ax.axhline(0.0, color="C3", lw=0.8, ls="--")
    ax.set_ylabel("clearance [m] (min over links)")
    _lines(axes[2, 0], t, qd, "joint velocity [rad/s]")
    _lines(axes[2, 1], t, qdd, "joint acceleration [rad/s²]")
    for ax in axes[2]:
        ax.set_xlabel("t [s]")
    for ax in axes.flat:
        ax.grid(True, alpha=0.3)
    fig.suptitle(title)
    save(fig, path)


def snapshots(
    scene: Scene, trace: Mapping[str, np.ndarray], times: Sequence[float], title: str, path: Path
) -> None:
    """The arm drawn at several instants among the obstacles (Figs. 1.7, 1.10)."""
    q = joint_matrix(trace)
    t = trace["t"]
    ref = np.column_stack([trace["x_ref"], trace["y_ref"], trace["z_ref"]])
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    _obstacles_3d(ax, scene)
    ax.plot(*ref.T, "k--", lw=1.0, label="reference")
    shown = []
    for k, time in enumerate(times):
        n = int(np.argmin(np.abs(t - time)))
        arm = joint_points(scene, q[n])
        shown.append(arm)
        ax.plot(
            *arm.T,
            "o-",
            color=plt.cm.plasma(k / max(len(times) - 1, 1)),
            lw=2,
            ms=3,
            label=f"t = {t[n]:.1f} s",
        )
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    _equal_3d(ax, np.vstack([*shown, ref]))
    ax.legend(fontsize=7)
    fig.suptitle(title)
    save(fig, path)


def joint_matrix(trace: Mapping[str, np.ndarray]) -> np.ndarray:
    """The q_1 … q_m columns of a trace as a (times, m) array."""
    names = sorted((k for k in trace if k.startswith("q_")), key=lambda k: int(k[2:]))
    return np.column_stack([trace[k] for k in names])


def _obstacle_hulls(scene: Scene) -> list[tuple[np.ndarray, np.ndarray]]:
    """(world vertices, hull triangles) of every obstacle part at t = 0."""
    hulls = []
    for obstacle in scene.obstacles:
        pose = obstacle.pose_at(0.0)
        for part in obstacle.parts:
            vertices = transform_points(pose, part.vertices)
            hulls.append((vertices, ConvexHull(vertices).simplices))
    return hulls


def _obstacles_3d(ax: plt.Axes, scene: Scene) -> None:
    for vertices, faces in _obstacle_hulls(scene):
        ax.add_collection3d(
            Poly3DCollection(vertices[faces], alpha=0.35, facecolor="0.6", edgecolor="0.4", lw=0.2)
        )


def _obstacles_top(ax: plt.Axes, scene: Scene) -> None:
    for vertices, _ in _obstacle_hulls(scene):
        outline = ConvexHull(vertices[:, :2])
        xy = vertices[outline.vertices, :2]
        ax.fill(xy[:, 0], xy[:, 1], color="0.6", alpha=0.4)


def _equal_3d(ax: plt.Axes, points: np.ndarray) -> None:
    """Equal scale on all three axes around the plotted points."""
    centre = (points.max(0) + points.min(0)) / 2
    half = (points.max(0) - points.min(0)).max() / 2 + 0.05
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)


def _lines(ax: plt.Axes, t: np.ndarray, values: np.ndarray, label: str) -> None:
    for j in range(values.shape[1]):
        ax.plot(t, values[:, j], lw=0.8, label=f"joint {j + 1}")
    ax.set_ylabel(label)
    ax.legend(fontsize=6, ncol=2)
