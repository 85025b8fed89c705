"""The clearance summary behind `articula scene check`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from articula.errors import ConfigError
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml


def parse_q(text: str) -> np.ndarray:
    """Joint values from "q1,q2,..." [rad]."""
    try:
        return np.array([float(v) for v in text.replace(" ", "").split(",") if v != ""])
    except ValueError:
        raise ConfigError("--q", f"expected comma-separated numbers (got {text!r})") from None


def check_scene(path: Path, q_text: str | None = None, metric: str = "gjk") -> dict[str, Any]:
    """End-effector position, clearances per link and obstacle, and whether anything collides."""
    spec = load_scene_spec(load_toml(path), str(path))
    if metric not in ("gjk", "vertex"):
        raise ConfigError("--metric", f"unknown metric {metric!r}; choose gjk or vertex")
    scene, q0 = build_scene(spec, path.parent, metric="vertex" if metric == "vertex" else "gjk")
    q = q0 if q_text is None else scene.robot.check_q(parse_q(q_text), "--q")
    d = scene.distances(q)
    min_clearance = float(d.min()) if d.size else float("inf")
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
        "collides": bool(min_clearance < 0.0),
        "within_limits": bool(np.all((q >= scene.robot.lower) & (q <= scene.robot.upper))),
        "metric": metric,
    }
