"""A plan config's file paths (URDF, package folders, obstacle meshes, trajectory CSV) made
absolute, so that a run folder's copy of the config still finds them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from articula.scene.config import PACKAGE_URI, resolve_path

__all__ = ["absolute_paths"]


def absolute_paths(data: dict[str, Any], base_dir: Path) -> dict[str, Any]:
    """The config with its URDF, package folders, obstacle meshes and trajectory CSV made
    absolute from `base_dir`, so that a run folder's config.toml still finds them.

    Args:
        data: the config's tables as read from TOML (not modified).
        base_dir: folder the relative paths are resolved from.

    Returns:
        A copy of the config with those paths absolute (package:// paths kept).
    """

    def absolute(path: Any) -> Any:
        if not isinstance(path, str) or path.startswith(PACKAGE_URI):
            return path  # a package path is the same on every machine
        return str(resolve_path(base_dir, path).resolve())

    out = dict(data)
    if isinstance(data.get("robot"), dict):
        robot = dict(data["robot"])
        if "urdf" in robot:
            robot["urdf"] = absolute(robot["urdf"])
        if isinstance(robot.get("package_dirs"), list):
            robot["package_dirs"] = [absolute(d) for d in robot["package_dirs"]]
        out["robot"] = robot
    if isinstance(data.get("obstacles"), list):
        out["obstacles"] = [
            {**o, "mesh": absolute(o["mesh"])} if isinstance(o, dict) and "mesh" in o else o
            for o in data["obstacles"]
        ]
    trajectory = data.get("trajectory")
    if isinstance(trajectory, dict) and "path" in trajectory:
        out["trajectory"] = {**trajectory, "path": absolute(trajectory["path"])}
    return out
