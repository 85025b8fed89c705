"""Published joint limits (robots.datasheets): the table, how a datasheet combines with the
URDF ([robot] datasheet, or the joint names), the record's kept limits and their sources, and
a Franka Panda planned by every method within Franka's published acceleration and jerk."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.experiments.plan import PlanConfig, run_plan
from articula.loops.online import OnlineController
from articula.planning.kept_limits import kept_limits
from articula.robots.datasheets import DATASHEETS, datasheet, match_joint_names
from articula.robots.limits import published_or_rule, tighter
from articula.scene.config import build_scene
from articula.validation import parse_model
from tests.arms import arm_scene, panda_robot
from tests.planning.test_safe_commands import METHODS

# Franka's "Limits for Panda" table (frankaemika.github.io/docs/control_parameters.html),
# typed here a second time as the oracle.
PANDA_ACCELERATION = np.array([15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0])  # [rad/s²]
PANDA_JERK = np.array([7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0])  # [rad/s³]
PANDA_SPEED = np.array([2.175] * 4 + [2.61] * 3)  # [rad/s]
PANDA_SHEET = ["datasheet franka-panda"] * 7
JERK = "velocity+acceleration+jerk"
UR_NAMES = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
            "wrist_2_joint", "wrist_3_joint"]  # fmt: skip


def config(robot: dict | None = None, **planner) -> PlanConfig:
    """The Panda tight scene (tests.arms), with `robot` keys and [planner] keys changed."""
    data = arm_scene("panda", duration=6.0)
    data["robot"] |= robot or {}
    data["planner"] |= planner
    return parse_model(PlanConfig, data, "scene")


def test_every_datasheet_has_one_entry_per_joint_and_sane_values():
    for sheet in DATASHEETS.values():
        for values in (sheet.lower, sheet.upper, sheet.acceleration, sheet.jerk, sheet.effort):
            assert len(values) == sheet.nq, sheet.name
        for low, high in zip(sheet.lower, sheet.upper, strict=True):
            assert (low is None) == (high is None) and (low is None or low < high)
        assert all(v is not None and v > 0 for v in sheet.velocity + sheet.effort)
        assert sheet.source


def test_the_panda_entry_is_franka_s_table_and_ur_publishes_no_acceleration():
    panda = DATASHEETS["franka-panda"]
    np.testing.assert_array_equal(panda.acceleration, PANDA_ACCELERATION)
    np.testing.assert_array_equal(panda.jerk, PANDA_JERK)
    np.testing.assert_array_equal(panda.velocity, PANDA_SPEED)
    assert panda.lower[3] == -3.0718 and panda.upper[3] == -0.0698
    for name in ("ur3e", "ur5e", "ur10e", "ur16e", "ur5", "ur10"):
        sheet = DATASHEETS[name]
        assert sheet.acceleration == (None,) * 6 and sheet.jerk == (None,) * 6
        assert sheet.upper == (2 * math.pi,) * 6  # ±360° on every joint
    assert DATASHEETS["ur10e"].velocity[:2] == (2 * math.pi / 3,) * 2  # 120°/s


def test_joint_names_pick_an_arm_only_when_no_other_shares_them():
    assert match_joint_names([f"panda_joint{i}" for i in range(1, 8)]).name == "franka-panda"
    assert match_joint_names([f"fr3_joint{i}" for i in range(1, 8)]).name == "franka-fr3"
    assert match_joint_names(UR_NAMES) is None  # every UR size has these names
    assert match_joint_names([f"panda_joint{i}" for i in range(1, 7)]) is None


def test_tighter_takes_the_smaller_limit_and_names_the_one_that_binds():
    urdf = np.array([2.0, 1.0, np.inf, 3.0])
    values, sources = tighter(urdf, [1.5, 1.2, 4.0, None], "datasheet x")
    np.testing.assert_array_equal(values, [1.5, 1.0, 4.0, 3.0])
    assert sources == ("datasheet x", "urdf", "datasheet x", "urdf")
    _, tie = tighter(np.array([2.0]), [2.0], "datasheet x")
    assert tie == ("datasheet x",)  # the maker's number, which the URDF repeats


def test_published_or_rule_falls_back_to_the_rise_time_per_joint():
    values, sources = published_or_rule([5.0, None], np.array([2.0, 1.0]), 0.25, "accel_time",
                                        "x")  # fmt: skip
    np.testing.assert_array_equal(values, [5.0, 4.0])
    assert sources == ("datasheet x", "default rule (accel_time = 0.25 s)")
    values, sources = published_or_rule(None, np.array([2.0, 0.0]), 0.5, "jerk_time", None)
    np.testing.assert_array_equal(values, [4.0, np.inf])  # no speed limit: no acceleration's
    assert sources == ("default rule (jerk_time = 0.5 s)",) * 2


def test_the_panda_s_joint_names_bring_franka_s_limits():
    scene, _ = build_scene(config(), Path("."))
    robot = scene.robot
    assert robot.datasheet == (
        "franka-panda (matched by the joint names panda_joint1..panda_joint7)"
    )
    np.testing.assert_array_equal(robot.acceleration_limit, PANDA_ACCELERATION)
    np.testing.assert_array_equal(robot.jerk_limit, PANDA_JERK)
    # pybullet_data's URDF allows joints 1-7 more range than Franka does: the datasheet binds.
    assert robot.upper[3] == -0.0698 and robot.lower[5] == -0.0175
    assert robot.limit_sources["position"] == tuple(PANDA_SHEET)
    np.testing.assert_array_equal(robot.model.effortLimit, [87.0] * 4 + [12.0] * 3)


def test_a_start_the_urdf_allows_but_franka_does_not_is_refused_naming_the_source():
    scene, q0 = build_scene(config(), Path("."))
    controller = OnlineController.from_spec(scene, config(method="qp").planner)
    q0[3] = -0.03  # within the URDF's joint 4 (up to 0), beyond Franka's -0.0698
    with pytest.raises(InfeasibleError, match=r"panda_joint4 = -0.0300 .*datasheet franka-panda"):
        controller.reset(q0)


def test_without_a_datasheet_the_urdf_and_the_default_rules_hold():
    scene, _ = build_scene(config({"datasheet": "none"}), Path("."))
    robot = scene.robot
    assert robot.datasheet is None
    np.testing.assert_allclose(robot.acceleration_limit, PANDA_SPEED / 0.25)  # 8.7 on joint 2
    assert robot.upper[3] == 0.0  # the URDF's
    record = kept_limits(config({"datasheet": "none"}).planner, robot)
    assert record["sources"] == {
        "velocity": ["urdf"] * 7,
        "acceleration": ["default rule (accel_time = 0.25 s)"] * 7,
    }
    assert record["datasheet"] is None


def test_a_datasheet_combines_with_another_urdf_joint_by_joint():
    """A 6-joint xArm6 given the UR5e's datasheet: each speed and effort limit is the smaller
    of the two, its source the one that binds; acceleration by the default rule (UR publishes
    none)."""
    data = arm_scene("xarm")
    plain, _ = build_scene(parse_model(PlanConfig, data, "scene"), Path("."))
    data["robot"] |= {"datasheet": "ur5e"}
    scene, _ = build_scene(parse_model(PlanConfig, data, "scene"), Path("."))
    robot, sheet = scene.robot, DATASHEETS["ur5e"]
    for key, urdf, published in (
        ("velocity", plain.robot.velocity_limit, sheet.velocity),
        ("effort", plain.robot.model.effortLimit, sheet.effort),
    ):
        now = robot.velocity_limit if key == "velocity" else robot.model.effortLimit
        np.testing.assert_array_equal(now, np.minimum(urdf, published))
        binds = [p <= u for p, u in zip(published, urdf, strict=True)]
        assert list(robot.limit_sources[key]) == ["datasheet ur5e" if b else "urdf" for b in binds]
    np.testing.assert_allclose(robot.acceleration_limit, robot.velocity_limit / 0.25)
    assert robot.datasheet == "ur5e ([robot] datasheet)"


def test_user_limits_override_the_datasheet_and_the_record_says_so():
    user = config({"acceleration_limits": 5.0, "jerk_limits": [900.0] * 7}, limits=JERK)
    scene, _ = build_scene(user, Path("."))
    record = kept_limits(user.planner, scene.robot)
    assert record["acceleration"] == [5.0] * 7 and record["jerk"] == [900.0] * 7
    assert record["sources"] == {"velocity": PANDA_SHEET, "acceleration": ["user"] * 7,
                                 "jerk": ["user"] * 7}  # fmt: skip
    assert record["datasheet"].startswith("franka-panda (matched")


def test_the_record_lists_only_the_limits_the_planner_keeps():
    scene, _ = build_scene(config(), Path("."))
    robot = scene.robot
    kept = config(max_acceleration=3.0, velocity_scale=0.5).planner
    record = kept_limits(kept, robot)  # the default limits: velocity+acceleration, no jerk
    assert set(record) == {"velocity", "acceleration", "sources", "datasheet"}
    np.testing.assert_allclose(record["velocity"], 0.5 * PANDA_SPEED)
    assert record["acceleration"] == [3.0] * 7
    assert record["sources"] == {"velocity": PANDA_SHEET, "acceleration": ["user"] * 7}
    assert set(kept_limits(config(limits="velocity").planner, robot)) == {
        "velocity", "sources", "datasheet"}  # fmt: skip
    # With no limits BAORNN keeps none; the baselines' solvers still keep the speeds.
    assert kept_limits(config(limits="none", method="baornn").planner, robot)["sources"] == {}
    assert "velocity" in kept_limits(config(limits="none", method="qp").planner, robot)


@pytest.mark.parametrize("name", ["franka-kuka", "panda"])
def test_an_unknown_datasheet_names_the_key_and_the_known_arms(name):
    with pytest.raises(ConfigError, match=r"robot\.datasheet.*franka-panda.*ur10e"):
        build_scene(config({"datasheet": name}), Path("."))


def test_a_datasheet_for_another_number_of_joints_is_refused():
    with pytest.raises(ConfigError, match=r"robot\.datasheet.*has 6 joints but the robot has 7"):
        build_scene(config({"datasheet": "ur5e"}), Path("."))
    with pytest.raises(ConfigError, match="datasheet"):
        datasheet("kinova-gen3", 6)


@pytest.mark.slow_cases(keep=("qp",))
@pytest.mark.parametrize("method", METHODS)
def test_a_panda_is_commanded_within_franka_s_published_limits(method):
    """Every method on the Panda tight scene with the jerk limits kept: every commanded
    acceleration and jerk (second and third differences of the plan, from rest at q0) within
    Franka's table, and the record says where each limit came from."""
    data = arm_scene("panda", duration=6.0)
    data["robot"] |= {"datasheet": "franka-panda"}
    data["planner"] |= {"method": method, "tolerance": 10.0, "limits": JERK}
    result = run_plan(parse_model(PlanConfig, data, "scene"))
    q0, dt = np.array(panda_robot()["q0"]), 0.01
    q = np.column_stack([result.trace[f"q_{j + 1}"] for j in range(7)])
    q = np.vstack([q0, q0, q0, q])  # at rest at q0 before the first command
    acceleration = np.abs(np.diff(q, 2, axis=0)) / dt**2
    jerk = np.abs(np.diff(q, 3, axis=0)) / dt**3
    assert np.all(acceleration <= PANDA_ACCELERATION * (1 + 1e-9))
    assert np.all(jerk <= PANDA_JERK * (1 + 1e-9))
    assert np.all(np.abs(np.diff(q, axis=0)) / dt <= PANDA_SPEED * (1 + 1e-9))
    assert np.max(acceleration / PANDA_ACCELERATION) > 0.1  # the arm did move
    limits = result.details["limits"]
    assert limits["sources"] == {"velocity": PANDA_SHEET, "acceleration": PANDA_SHEET,
                                 "jerk": PANDA_SHEET}  # fmt: skip
    assert limits["datasheet"] == "franka-panda ([robot] datasheet)"
    np.testing.assert_array_equal(limits["acceleration"], PANDA_ACCELERATION)
