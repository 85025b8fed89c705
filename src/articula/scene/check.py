"""The clearance summary behind `articula scene check`."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from articula.errors import ConfigError
from articula.scene.config import build_scene, load_scene_spec, robot_self_collision
from articula.scene.scene import Scene
from articula.validation import load_toml

MAX_ROWS = 100_000  # configurations of one --q-file


def parse_q(text: str) -> np.ndarray:
    """Joint values from "q1,q2,..." [rad].

    Args:
        text: comma-separated joint values, as given to --q [rad].

    Returns:
        The joint values, shape (n,) [rad].
    """
    try:
        return np.array([float(v) for v in text.replace(" ", "").split(",") if v != ""])
    except ValueError:
        raise ConfigError("--q", f"expected comma-separated numbers (got {text!r})") from None


def read_q_file(path: Path, nq: int, max_rows: int = MAX_ROWS) -> np.ndarray:
    """Configurations [rad], one per row, from a CSV (a header line is allowed) or Parquet file
    of `nq` numeric columns, or from the columns q_1..q_nq of a file that names them (a run's
    trace.parquet: each row one control period's commanded joints, in the order of its t; its
    other columns, the twin's measured qm_* among them, are left out).

    Args:
        path: the .csv or .parquet file (--q-file).
        nq: number of joints, the columns each row must have.
        max_rows: most configurations the file may hold.

    Returns:
        The configurations, shape (rows, nq) [rad].
    """
    if not path.is_file():
        raise ConfigError("--q-file", f"{path}: file not found")
    try:
        if path.suffix.lower() == ".parquet":
            import pyarrow.parquet as pq

            table = pq.read_table(path)
            columns = _joint_columns(path, table.column_names, nq) or table.column_names
            rows = np.column_stack([table[c].to_numpy() for c in columns])
        else:
            text = path.read_text(encoding="utf-8").splitlines()
            header = text[0].split(",") if text and not _numeric(text[0]) else None
            lines = text[1:] if header is not None else text
            body = [line.split(",") for line in lines if line.strip()]
            names = [name.strip() for name in header or ()]
            joints = _joint_columns(path, names, nq)
            if joints:
                body = [[cells[names.index(c)] for c in joints] for cells in body]
            rows = np.array([[float(v) for v in cells] for cells in body])
    except ConfigError:
        raise  # the joint columns named, but not this robot's
    except (ValueError, IndexError, OSError, ImportError) as exc:
        raise ConfigError("--q-file", f"{path}: not a table of numbers ({exc})") from None
    if rows.ndim != 2 or rows.shape[1] != nq or not 0 < len(rows) <= max_rows:
        raise ConfigError(
            "--q-file",
            f"{path}: needs 1 to {max_rows} rows of {nq} joint values (got shape {rows.shape})",
        )
    return rows


def _joint_columns(path: Path, names: list[str], nq: int) -> list[str] | None:
    """q_1..q_nq when the file's columns name joints; None when they name none."""
    joints = [name for name in names if re.fullmatch(r"q_[0-9]+", name)]
    if not joints:
        return None
    wanted = [f"q_{j + 1}" for j in range(nq)]
    if sorted(joints) != sorted(wanted):
        raise ConfigError(
            "--q-file",
            f"{path}: has the joint columns {', '.join(joints)}; the scene's robot has {nq} "
            f"joints (q_1 to q_{nq}): give a run of this robot",
        )
    return wanted


def _numeric(line: str) -> bool:
    try:
        [float(v) for v in line.split(",")]
    except ValueError:
        return False
    return True


def check_scene(
    path: Path, q_text: str | None = None, metric: str = "gjk", q_file: Path | None = None
) -> dict[str, Any]:
    """End-effector position, clearances per link and obstacle, and whether anything collides,
    at q0, at --q, or (with --q-file) at every row of a file: {"configurations": [...]}.

    Args:
        path: the scene TOML file.
        q_text: joint values "q1,q2,..." [rad] (--q); None for the scene's q0.
        metric: "gjk" (exact convex distance) or "vertex" (the book's Sect. 1.3.3 formula).
        q_file: a CSV or Parquet file of configurations (--q-file), or None.

    Returns:
        The summary of the configuration: q [rad], ee_position [m], min_clearance [m],
        link_clearance and obstacle_clearance by name [m], self_clearance [m],
        self_closest_pair, self_collides, self_collision_checked, collides, within_limits,
        outside_limits (each joint outside its limits: joint, value, lower, upper [rad]) and
        metric; with `q_file`, {"configurations": [one summary per row]}.
    """
    spec = load_scene_spec(load_toml(path), str(path))
    if metric not in ("gjk", "vertex"):
        raise ConfigError("--metric", f"unknown metric {metric!r}; choose gjk or vertex")
    if q_text is not None and q_file is not None:
        raise ConfigError("--q-file", "give --q or --q-file, not both")
    scene, q0 = build_scene(spec, path.parent, metric="vertex" if metric == "vertex" else "gjk")
    # Self distances over the pairs the scene checks; with self_collision off, over the pairs
    # it would check, so that the answer says whether turning it on matters.
    itself = scene
    if not scene.self_pairs:
        checked = robot_self_collision(spec, scene.robot).checked
        itself = Scene(scene.robot, [], metric=scene.metric, self_pairs=checked)
    if q_file is not None:
        rows = read_q_file(q_file, scene.robot.nq)
        return {
            "configurations": [
                _check(scene, itself, scene.robot.check_q(q, "--q-file"), metric) for q in rows
            ]
        }
    q = q0 if q_text is None else scene.robot.check_q(parse_q(q_text), "--q")
    return _check(scene, itself, q, metric)


def _check(scene: Scene, itself: Scene, q: np.ndarray, metric: str) -> dict[str, Any]:
    """The summary of one configuration; `itself` holds the link pairs to check."""
    d = scene.distances(q)
    min_clearance = float(d.min()) if d.size else float("inf")
    d_self = itself.self_distances(q)
    closest = int(np.argmin(d_self)) if d_self.size else None
    self_clearance = float(d_self[closest]) if closest is not None else float("inf")
    robot = scene.robot
    outside = np.flatnonzero((q < robot.lower) | (q > robot.upper))
    return {
        "q": q.tolist(),
        "ee_position": scene.robot.ee_position(q).tolist(),
        "min_clearance": min_clearance,
        "link_clearance": {
            name: float(row.min()) if row.size else float("inf")
            for name, row in zip(scene.link_names, d, strict=True)
        },
        "obstacle_clearance": {
            o.name: float(col.min()) for o, col in zip(scene.obstacles, d.T, strict=True)
        },
        "self_clearance": self_clearance,
        "self_closest_pair": None if closest is None else list(itself.self_pair_names[closest]),
        "self_collides": bool(self_clearance < 0.0),
        "self_collision_checked": bool(scene.self_pairs),
        "collides": bool(min_clearance < 0.0 or (scene.self_pairs and self_clearance < 0.0)),
        "within_limits": not outside.size,
        "outside_limits": [
            {
                "joint": robot.joint_names[j],
                "value": float(q[j]),
                "lower": float(robot.lower[j]),
                "upper": float(robot.upper[j]),
            }
            for j in outside
        ],
        "metric": metric,
    }
