"""A scene file read and checked for `articula live`: its plan config (the method and plant
asked for on the command line), scene, start and reference, before any server opens."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from articula.errors import ArticulaError
from articula.experiments.plan import PlanConfig, build_plan
from articula.planning.approach import Approach
from articula.planning.config_files import absolute_paths
from articula.scene.scene import Scene
from articula.validation import load_toml

__all__ = ["DEFAULT_SERVO_RATE", "PLANTS", "LiveScene"]

PLANTS = ("mujoco", "none")  # `live --plant`
DEFAULT_SERVO_RATE = 1000.0  # [Hz] the twin's servo rate where the scene file has no [servo]


@dataclass
class LiveScene:
    """A scene file read and checked for `live`: its plan config (the method given, if one
    was), scene, start configuration [rad] and end-effector path.

    Attributes:
        config: the scene file as a plan config (its paths absolute).
        scene: the robot and obstacles.
        q0: the start configuration, shape (n,) [rad].
        targets: the end-effector's reference (t [s] -> target): the approach from the tool
            to the path's start, then the path.
        validated: the plan config as validated ([plant] and [servo] included).
    """

    config: dict[str, Any]
    scene: Scene
    q0: np.ndarray
    targets: Approach
    validated: PlanConfig

    @classmethod
    def load(
        cls, scene_file: Path, method: str | None = None, plant: str | None = None
    ) -> LiveScene:
        """Read scene_file; an ArticulaError (before any server opens) when its planner does
        not validate or cannot start from its q0.

        Args:
            scene_file: a scene TOML with [planner] and [trajectory] tables.
            method: the planner method to use instead of the file's; None: the file's.
            plant: "mujoco" (the dynamics twin, at the file's [servo] rate or 1 kHz) or "none"
                (the arm is where it was told) instead of the file's [plant]; None: the file's.

        Returns:
            The scene file, read and checked.
        """
        config = _plan_config(scene_file)
        if method is not None:
            config["planner"]["method"] = method
        if plant == "none":
            config.pop("plant", None)
        elif plant is not None:
            config["plant"] = {**config.get("plant", {}), "type": plant}
            config.setdefault("servo", {"rate": DEFAULT_SERVO_RATE})
        plan = build_plan(config, scene_file.parent, str(scene_file))  # named as `plan` does
        plan.controller(live_obstacles=True)  # a start it refuses is refused here
        config["planner"]["limits"] = plan.spec.limits  # a stream's jerk limits, as `plan`'s
        return cls(config, plan.scene, plan.q0, plan.reference, plan.config)


def _plan_config(scene_file: Path) -> dict[str, Any]:
    """A scene file as a plan config, its file paths absolute (so a recorded run finds them)."""
    data = load_toml(scene_file)
    if "trajectory" not in data:
        raise ArticulaError(f"{scene_file}: live needs a [trajectory] table (the path to follow)")
    data.setdefault("planner", {})
    return absolute_paths(data, scene_file.resolve().parent)
