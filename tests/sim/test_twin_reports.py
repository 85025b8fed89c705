"""What the twin reports, and how it fails: a joint held at its effort limit exits 2 naming the
joint (a UR10 whose URDF efforts are scaled down); the measured tool is compared with the
reference at the same time (recomputed from the trace with Pinocchio on the URDF); the
stream's braking tail is played, so the twin ends at rest where the stream stops; the stream's
clearance is the minimum over its samples (coal on the URDF's mesh hulls) and one below its
floor exits 2 naming the pair; the twin's failures come in a stated order, contacts left to
exit 4."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from xml.etree import ElementTree

import coal
import numpy as np
import pinocchio as pin
import pyarrow.parquet as pq
import pytest
import tomli_w

from articula.cli import main
from articula.experiments.plan import PlanConfig, build_plan, run_plan
from articula.loops.sampled_clearance import STREAM_TOLERANCE, clearance_failure
from articula.loops.servo import ServoLimits, ServoStream, servo_trace
from articula.runs.folders import SERVO
from articula.validation import parse_model
from tests.arms import arm_scene
from tests.oracles import urdf_hull_clearances

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install -e ".[sim]"')

from articula.sim.twin_arm import TwinArm

SCALE = 0.25  # of the UR10's effort limits: less than the stream's peaks ask of the elbow


def _weak_ur10(tmp_path: Path) -> tuple[Path, dict[str, float]]:
    """A copy of the UR10's URDF with every effort limit scaled by SCALE, and those limits."""
    robot = arm_scene("ur10")["robot"]
    tree = ElementTree.parse(robot["urdf"])
    efforts = {}
    for joint in tree.getroot().iter("joint"):
        limit = joint.find("limit")
        if limit is not None and joint.get("type") != "fixed":
            limit.set("effort", repr(SCALE * float(limit.get("effort"))))
            efforts[joint.get("name")] = float(limit.get("effort"))
    urdf = tmp_path / "ur10_weak.urdf"
    tree.write(urdf)
    return urdf, efforts


def _twin_scene(tmp_path: Path, urdf: Path | None = None, duration: float = 2.0) -> Path:
    """arm_scene("ur10") under the twin at 1 kHz for `duration` [s] of path, as a scene file."""
    data = arm_scene("ur10", duration)
    if urdf is not None:
        data["robot"] = {**data["robot"], "urdf": str(urdf)}
        data["obstacles"] = []  # a weak arm sags: no obstacle for it to touch (that exits 4)
    data["planner"] = {**data["planner"], "method": "qp", "settle": 0.5}
    data |= {"servo": {"rate": 1000}, "plant": {"type": "mujoco"}}
    scene = tmp_path / "scene.toml"
    scene.write_text(tomli_w.dumps(data))
    return scene


def test_a_joint_at_its_effort_limit_exits_2_naming_it(cli, tmp_path):
    urdf, efforts = _weak_ur10(tmp_path)
    out = tmp_path / "run"
    proc = cli("plan", _twin_scene(tmp_path, urdf), "--out", out, "--json")
    assert proc.returncode == 2, proc.stderr
    m = json.loads(proc.stdout)["metrics"]
    joint = m["torque_saturated_joint"]
    assert len(proc.stderr.strip().splitlines()) == 1
    assert joint in proc.stderr and "effort limit" in proc.stderr
    assert m["plant_contacts"] == 0 and m["torque_saturated_s"] >= m["torque_saturated_joint_s"] > 0
    # The trace's torques (one per period end) reach the copy's effort limit on that joint.
    config = parse_model(PlanConfig, tomllib.loads((tmp_path / "scene.toml").read_text()), "s")
    index = build_plan(config, tmp_path).scene.robot.joint_names.index(joint)
    tau = pq.read_table(out / "trace.parquet").column(f"tau_{index + 1}").to_numpy()
    assert np.max(np.abs(tau)) == pytest.approx(efforts[joint], rel=1e-9)
    assert (out / "record.json").exists()


@pytest.fixture(scope="module")
def ur10_run(tmp_path_factory):
    """arm_scene("ur10") with qp for 2 s of path under the twin: (result, plan setup)."""
    folder = tmp_path_factory.mktemp("ur10")
    data = tomllib.loads(_twin_scene(folder).read_text())
    config = parse_model(PlanConfig, data, "ur10")
    return run_plan(config), build_plan(config, folder)


def test_the_measured_tool_is_compared_with_the_reference_at_the_same_time(ur10_run):
    result, plan = ur10_run
    m, trace = result.metrics, result.trace
    robot = plan.scene.robot
    # Pinocchio on the URDF itself: the tool measured at the end of period k is at time
    # t[k] + dt = t[k + 1], where the trace's reference is x_ref[k + 1].
    model = pin.buildModelFromUrdf(plan.config.robot.urdf)
    data, frame = model.createData(), model.getFrameId(robot.ee_frame)
    qm = np.column_stack([trace[f"qm_{j + 1}"] for j in range(model.nq)])
    tool = []
    for q in qm:
        pin.framesForwardKinematics(model, data, q)
        tool.append(data.oMf[frame].translation.copy())
    x_ref = np.column_stack([trace[c] for c in ("x_ref", "y_ref", "z_ref")])
    settled = trace["t"][1:] >= m["approach_s"] + m["settle_s"]
    error = np.linalg.norm(np.array(tool)[:-1] - x_ref[1:], axis=1)[settled]
    assert m["plant_rms_error"] == pytest.approx(np.sqrt(np.mean(error**2)), rel=1e-9)
    assert m["plant_max_error"] == pytest.approx(np.max(error), rel=1e-9)
    late = np.linalg.norm(np.array(tool)[:-1] - x_ref[:-1], axis=1)[settled]
    assert abs(np.sqrt(np.mean(late**2)) - m["plant_rms_error"]) > 1e-4  # a period's lag shows


def test_the_tail_is_played_and_the_twin_ends_at_rest_where_the_stream_stops(ur10_run):
    result, plan = ur10_run
    assert result.metrics["plant_tail_s"] > 0 and result.metrics["plant_final_speed"] < 1e-3
    # The set-points again, open loop, on a fresh twin: it ends where the stream ends.
    n, dt = plan.q0.size, plan.spec.dt
    setpoints = np.column_stack([result.trace[f"q_{j + 1}"] for j in range(n)])
    arm = TwinArm(plan.scene, plan.q0, dt, 1000.0)
    for q in setpoints:
        arm(q)
    arm.brake()
    stream = servo_trace(
        setpoints, plan.q0, dt, ServoStream(ServoLimits.of(plan.scene.robot), dt, 1000.0)
    )
    tail = len(stream.t) - 1 - 10 * len(setpoints)  # the stream's braking and holding ticks
    assert arm.tail_periods * 10 > tail > 0
    assert len(arm.ticks) == 1 + 10 * (len(setpoints) + arm.tail_periods)
    assert np.max(np.abs(arm.speed)) < 1e-3
    assert np.max(np.abs(arm.ticks[-1] - stream.q[-1])) < 1e-4


def test_the_stream_clearance_is_the_minimum_over_its_samples_by_coal(ur10_run):
    result, plan = ur10_run
    m, servo, scene = result.metrics, result.tables[SERVO], plan.scene
    q = np.column_stack([servo[f"q_{j + 1}"] for j in range(plan.q0.size)])
    ball = arm_scene("ur10")["obstacles"][0]
    pose = np.eye(4)
    pose[:3, 3] = ball["position"]
    robot = plan.config.robot
    obstacle, self_ = urdf_hull_clearances(
        robot.urdf, robot.package_dirs, scene.robot.joint_names, q,
        [(coal.Sphere(ball["sphere"]), pose)], scene.self_pair_names,
    )  # fmt: skip
    assert m["stream_min_clearance"] == pytest.approx(obstacle, abs=1e-6)
    assert m["stream_min_self_clearance"] == pytest.approx(self_, abs=1e-6)
    assert m["stream_min_clearance"] >= plan.spec.d_min - STREAM_TOLERANCE
    assert m["stream_min_self_clearance"] >= scene.self_d_min - STREAM_TOLERANCE


def test_a_stream_below_its_floor_fails_naming_the_pair_and_a_collision_is_left_to_exit_4():
    metrics = {"stream_min_clearance": 0.0194, "stream_min_clearance_pair": "wrist_3_link / ball",
               "stream_min_clearance_at": 1.25, "stream_min_self_clearance": 0.0049,
               "stream_min_self_clearance_pair": "a / b", "stream_min_self_clearance_at": 2.0,
               "collisions": 0.0}  # fmt: skip
    why = clearance_failure(metrics, "stream", "the servo stream", (0.02, 0.005), 0.5e-3)
    assert "19.40 mm from wrist_3_link / ball at t = 1.250 s" in why
    assert "planner.d_min = 20 mm" in why
    assert clearance_failure(metrics, "stream", "it", (0.0199, 0.0054), 0.5e-3) is None
    why = clearance_failure(metrics, "stream", "it", (0.0199, 0.0055), 0.5e-3)
    assert "a / b" in why and "robot.self_d_min = 5.5 mm" in why
    assert clearance_failure(metrics | {"collisions": 3.0}, "stream", "it", (1, 1), 0) is None


def test_a_stream_that_dips_more_than_its_tolerance_exits_2_naming_it(
    tmp_path, monkeypatch, capsys
):
    # No planner dips this far (the measured dips are < 0.1 mm): a floor 50 mm above d_min
    # stands in for a dip, through the same path a real one takes.
    monkeypatch.setattr("articula.experiments.plan.STREAM_TOLERANCE", -0.05)
    data = arm_scene("ur10", 3.0) | {"servo": {"rate": 1000}}
    scene, out = tmp_path / "scene.toml", tmp_path / "run"
    scene.write_text(tomli_w.dumps(data))
    with pytest.raises(SystemExit) as exit_:
        main(["plan", str(scene), "--out", str(out), "--json"])
    assert exit_.value.code == 2
    captured = capsys.readouterr()
    m = json.loads(captured.out)["metrics"]
    assert m["stream_min_clearance"] < data["planner"]["d_min"] + 0.05
    assert len(captured.err.strip().splitlines()) == 1
    assert "servo stream" in captured.err and m["stream_min_clearance_pair"] in captured.err
    assert (out / "record.json").exists() and (out / "servo.parquet").exists()


def test_the_twin_fails_on_saturation_then_clearance_then_error_and_leaves_contacts_to_exit_4():
    ok = {"plant_contacts": 0.0, "torque_saturated_s": 0.0, "torque_saturated_joint": None,
          "torque_saturated_joint_s": 0.0, "plant_min_clearance": 0.0195,
          "plant_min_clearance_pair": "wrist_3_link / ball", "plant_min_clearance_at": 1.5,
          "plant_min_self_clearance": None, "plant_rms_error": 0.004,
          "plant_max_error": 0.006}  # fmt: skip
    floors = (0.02, 0.005)
    assert TwinArm.failure(ok, 0.005, floors) is None  # 0.5 mm below d_min: within 1 mm
    far = ok | {"plant_rms_error": 0.0051}
    assert "5.10 mm RMS" in TwinArm.failure(far, 0.005, floors)
    close = far | {"plant_min_clearance": 0.0189}
    assert "18.90 mm from wrist_3_link / ball" in TwinArm.failure(close, 0.005, floors)
    held = close | {"torque_saturated_s": 0.25, "torque_saturated_joint": "elbow_joint",
                    "torque_saturated_joint_s": 0.2}  # fmt: skip
    assert "elbow_joint was at its effort limit for 0.200 s" in TwinArm.failure(held, 0.005, floors)
    assert TwinArm.failure(held | {"plant_contacts": 2.0}, 0.005, floors) is None
