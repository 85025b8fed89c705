"""`[plant] type = "mujoco"`: qp and baornn-improved drive the dynamics twin through the 1 kHz
stream, closing the loop on its measured joints, on the book's two-obstacle circle and a
Franka Panda among obstacles: no MuJoCo contact, torques within the effort limits, the
measured tool within 2 mm RMS of the path, and the measured motion clear of the obstacles by
coal on the URDF's own collision meshes (Pinocchio's geometry model, not articula's scene)."""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree

import coal
import numpy as np
import pinocchio as pin
import pytest

from articula.experiments.plan import PlanConfig, load_plan, run_plan
from articula.scene.config import build_scene
from articula.validation import parse_model
from tests.arms import CONFIGS, arm_scene

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"')

IIWA = Path(__file__).resolve().parents[2] / "src/articula/robots/data/iiwa14"


def _with_twin(data: dict, method: str) -> tuple[dict, PlanConfig]:
    """run_plan with `method` (10 s of path) under the twin at 1 kHz: (metrics, config)."""
    planner = {**data["planner"], "method": method, "duration": 10.0, "settle": 3.0,
               "tolerance": 10.0}  # fmt: skip
    data = {**data, "planner": planner, "servo": {"rate": 1000}, "plant": {"type": "mujoco"}}
    data.pop("experiment", None)
    config = parse_model(PlanConfig, data, "scene")
    result = run_plan(config)
    return result, config


def _urdf_clearance(urdf: Path, mesh_dirs: list[Path], config: PlanConfig, qs: np.ndarray):
    """Smallest distance between the URDF's collision meshes (Pinocchio + coal, the arm's
    joints as the URDF has them, locked ones at their values) and the obstacles, over qs."""
    full = pin.buildModelFromUrdf(str(urdf))
    geometry = pin.GeometryModel()
    pin.buildGeomFromUrdf(
        full, str(urdf), pin.GeometryType.COLLISION, geometry, [str(d) for d in mesh_dirs]
    )
    scene, _ = build_scene(config, Path("."))
    fixed = dict(config.robot.locked_joints)
    for joint in ElementTree.parse(urdf).getroot().iter("joint"):  # a mimic follows its joint
        mimic = joint.find("mimic")
        if mimic is not None and mimic.get("joint") in fixed:
            scale, offset = float(mimic.get("multiplier", 1)), float(mimic.get("offset", 0))
            fixed[joint.get("name")] = scale * fixed[mimic.get("joint")] + offset
    obstacles = [(part.geometry, obstacle.pose_at(0.0)) for obstacle in scene.obstacles
                 for part in obstacle.parts]  # fmt: skip
    data, gdata = full.createData(), geometry.createData()
    request, best = coal.DistanceRequest(), np.inf
    for q in qs:
        q_full = pin.neutral(full)
        values = {**fixed, **dict(zip(scene.robot.joint_names, q, strict=True))}
        for name, value in values.items():
            q_full[full.idx_qs[full.getJointId(name)]] = value
        pin.updateGeometryPlacements(full, data, geometry, gdata, q_full)
        for k, obj in enumerate(geometry.geometryObjects):
            link = coal.Transform3s(gdata.oMg[k].rotation, gdata.oMg[k].translation)
            for shape, T in obstacles:
                result = coal.DistanceResult()
                pose = coal.Transform3s(T[:3, :3], T[:3, 3])
                best = min(best, coal.distance(obj.geometry, link, shape, pose, request, result))
    return best


@pytest.fixture(scope="module")
def twin_runs():
    """(scene, method) -> (metrics, trace, config, URDF, mesh folders), each run once."""
    runs = {}

    def run(scene: str, method: str):
        if (scene, method) not in runs:
            if scene == "circle":
                data = load_plan(CONFIGS / "circle_two_obstacles.toml")
                urdf, dirs = IIWA / "iiwa14.urdf", [IIWA]
            else:
                data = arm_scene("panda")
                folder = Path(data["robot"]["urdf"]).parent
                urdf, dirs = folder / "panda.urdf", [folder]
            result, config = _with_twin(data, method)
            runs[scene, method] = (result.metrics, result.trace, config, urdf, dirs)
        return runs[scene, method]

    return run


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    ("scene", "method"),
    [
        ("circle", "qp"),
        ("panda", "qp"),
        ("circle", "baornn-improved"),
        ("panda", "baornn-improved"),
    ],
)
def test_the_twin_touches_nothing_within_its_effort_limits(twin_runs, scene, method):
    m, trace, config, urdf, dirs = twin_runs(scene, method)
    assert m["plant_contacts"] == 0 and m["max_torque_ratio"] < 1.0
    assert m["torque_saturated_s"] == 0 and m["plant_final_speed"] < 1e-3
    qm = np.column_stack([trace[f"qm_{j + 1}"] for j in range(7)])
    clearance = _urdf_clearance(urdf, dirs, config, qm[::5])
    assert clearance > 0.0 and m["plant_min_clearance"] > 0.0


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    ("scene", "method"),
    [
        ("circle", "qp"),
        ("panda", "qp"),
        ("circle", "baornn-improved"),
        ("panda", "baornn-improved"),
    ],
)
def test_the_twin_tracks_within_2_mm(twin_runs, scene, method):
    assert twin_runs(scene, method)[0]["plant_rms_error"] <= 0.002
