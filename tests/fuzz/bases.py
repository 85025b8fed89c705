"""Valid base inputs of every fuzzed command, each cheap to run (a fraction of a second).

Each config is validated by its experiment's own model and dumped back
(`model_dump(mode="json", exclude_none=True)` plus its `experiment` key), so the fuzzer
mutates the full schema, defaults included. Durations are tiny, so that a mutation the
command still accepts stays cheap; the planner's tolerance is large, so tracking quality
never decides the outcome, and the path starts at once (no approach from the tool). Files
the configs name (the rock mesh, a waypoint CSV) are written beside them by
`write_support_files`.
"""

from __future__ import annotations

import random
import shutil
from pathlib import Path
from typing import Any

from pydantic import BaseModel

import articula.book.ch1 as ch1
import articula.robots as robots
from articula.experiments.motor import CurrentControlConfig
from articula.experiments.plan import PlanConfig
from articula.experiments.pneunet import PneuNetPidConfig
from articula.experiments.six_chamber import DeactuationConfig
from articula.plants.dc_motor import PRESETS
from articula.scene.config import SceneSpec

ROCK = Path(ch1.__file__).parent / "configs" / "rock.stl"
MESH = "rock.stl"  # relative: found beside the config
CSV = "path.csv"
CSV_TEXT = "t,x,y,z\n0.0,0.0,0.6,0.5\n0.1,0.02,0.6,0.5\n0.2,0.02,0.6,0.52\n0.3,0.0,0.6,0.52\n"


def dump(name: str, model: type[BaseModel], data: dict[str, Any]) -> dict[str, Any]:
    """`data` validated by `model` and dumped with every default, plus its experiment key."""
    validated = model.model_validate(data)
    return {"experiment": name, **validated.model_dump(mode="json", exclude_none=True)}


GARBAGE = random.Random(0).randbytes(4096)


def write_support_files(folder: Path) -> None:
    """The files the base configs refer to, in the folder of the config, and two hostile ones
    that mutations name (garbage.stl: random bytes; empty.stl: nothing)."""
    shutil.copyfile(ROCK, folder / MESH)
    (folder / CSV).write_text(CSV_TEXT)
    (folder / "garbage.stl").write_bytes(GARBAGE)
    (folder / "empty.stl").write_bytes(b"")


MOTOR_CURRENT = dump("motor.current", CurrentControlConfig, {"duration": 0.2, "settle": 0.1})
PNEUNET_PID = dump("pneunet.pid", PneuNetPidConfig, {"trials": 2, "duration": 1.0})
SOFTARM_DAMPING = dump(
    "softarm.damping", DeactuationConfig, {"hold": 0.05, "after": 0.05, "dt": 1e-4}
)

ROBOT = {"builtin": "iiwa14", "q0": [0.0] * 7}
IIWA = Path(robots.__file__).parent / "data" / "iiwa14"
URDF_ROBOT = {
    "urdf": str(IIWA / "iiwa14.urdf"), "package_dirs": [str(IIWA)], "ee_frame": "iiwa_link_ee",
}  # fmt: skip
OBSTACLES = [
    {"name": "rock", "mesh": MESH, "scale": 1.0, "position": [-0.08, 0.30, 0.90]},
    {"name": "ball", "sphere": 0.05, "position": [0.5, 0.5, 0.2], "velocity": [0.0, 0.0, 0.01]},
    {"name": "crate", "box": [0.1, 0.2, 0.1], "position": [-0.5, -0.4, 0.3],
     "rpy": [0.0, 0.0, 0.3]},
    {"name": "post", "cylinder": [0.05, 0.4], "position": [0.6, -0.5, 0.2]},
    {"name": "pipe", "capsule": [0.04, 0.3], "position": [-0.6, 0.5, 0.2]},
]  # fmt: skip
CIRCLE = {
    "type": "circle", "center": [0.0, 0.6, 0.5], "axis_a": [1.0, 0.0, 0.0],
    "axis_b": [0.0, 0.0, 1.0], "radius": 0.2, "period": 50.0,
}  # fmt: skip
RECTANGLE = {
    "type": "rectangle", "period": 20.0,
    "vertices": [[0.0, 0.6, 0.5], [0.1, 0.6, 0.5], [0.1, 0.6, 0.6], [0.0, 0.6, 0.6]],
}  # fmt: skip
WAYPOINTS = {
    "type": "waypoints", "points": [[0.0, 0.6, 0.5], [0.02, 0.6, 0.5], [0.02, 0.6, 0.52]],
    "times": [0.0, 0.1, 0.3],
}  # fmt: skip
CSV_PATH = {"type": "csv", "path": CSV}
PLANNER = {"duration": 0.2, "settle": 0.1, "dt": 0.01, "tolerance": 10.0, "approach": "none"}


def _plan(
    method: str,
    trajectory: dict[str, Any],
    obstacles: list[dict[str, Any]],
    robot: dict[str, Any] = ROBOT,
) -> dict[str, Any]:
    data = {"robot": robot, "obstacles": obstacles, "trajectory": trajectory,
            "planner": {"method": method, **PLANNER}}  # fmt: skip
    return dump("baornn.plan", PlanConfig, data)


# Every planner and every kind of trajectory, among every kind of obstacle.
PLANS = {
    "baornn-circle": _plan("baornn", CIRCLE, OBSTACLES),
    "improved-rectangle": _plan("baornn-improved", RECTANGLE, OBSTACLES[:2]),
    "qp-waypoints": _plan("qp", WAYPOINTS, OBSTACLES[1:3]),
    "dls-csv": _plan("dls", CSV_PATH, OBSTACLES[3:]),
    "pinv-urdf": _plan("pinv", CIRCLE, OBSTACLES[:1], URDF_ROBOT),
    "baornn-no-obstacles": _plan("baornn", CIRCLE, []),
}


def _scene(robot: dict[str, Any], obstacles: list[dict[str, Any]]) -> dict[str, Any]:
    spec = SceneSpec.model_validate({"robot": robot, "obstacles": obstacles})
    return spec.model_dump(mode="json", exclude_none=True)


SCENES = {"builtin": _scene(ROBOT, OBSTACLES), "urdf": _scene(URDF_ROBOT, OBSTACLES[1:])}
Q0 = ",".join(["0"] * 7)

MOTOR_PARAMS = PRESETS["table4.2"].model_dump(mode="json")

# 4 runs of a few milliseconds each.
SWEEP = {
    "base": MOTOR_CURRENT,
    "grid": {"seed": [0, 1]},
    "runs": [{}, {"controller": {"filter_order": 2}}],
}
