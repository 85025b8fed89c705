"""Joint limits the arms' makers publish: position, speed, acceleration, jerk and effort.

Each entry is one arm's table as its maker states it, joint 1 (base) to joint n, SI units
(rad, rad/s, rad/s², rad/s³, N·m); None where the maker publishes no such limit. Sources:

- Franka Emika Panda (FER), "franka-panda": Franka's "Robot and interface specifications",
  section "Limits for Panda", https://frankaemika.github.io/docs/control_parameters.html
  (now "Control Interface Specification and Robot Limits", section "Limits for Franka Emika
  Robot (FER)", https://frankarobotics.github.io/docs/robot_specifications.html); the same
  numbers are libfranka 0.9's `include/franka/rate_limiting.h` (kMaxJointVelocity,
  kMaxJointAcceleration, kMaxJointJerk).
- Franka Research 3, "franka-fr3": the same page, section "Limits for Franka Research 3". Its
  speed limit depends on the joint's position; the speeds here are the fixed ("rectangular")
  limits Franka suggests for planners, which franka_description's
  `robots/fr3/joint_limits.yaml` also holds with the ranges and torques; acceleration and
  jerk from libfranka's `include/franka/rate_limiting.h` (FR3 releases, which cite that
  section).
- Universal Robots UR3e, UR5e, UR10e, UR16e ("ur3e", ...) and the CB3 UR5, UR10 ("ur5",
  "ur10"): each arm's user manual (e-Series version 5.8, CB3 version 3.13: every joint
  ±360°, the joint speeds) and UR's support article "Max. joint torques"
  (https://www.universal-robots.com/articles/ur-articles/max-joint-torques), as collected in
  Universal_Robots_ROS2_Description's `config/<type>/joint_limits.yaml`. UR publishes no
  joint acceleration or jerk limits ("acceleration limits are not publicly available"):
  they stay None.
- Kinova Gen3 7-DOF, "kinova-gen3": Kinova's own description, ros2_kortex
  `kortex_description/arms/gen3/7dof/urdf/gen3_macro.xacro` (speeds, torques; joints 1, 3,
  5 and 7 turn without end) and ros_kortex `GEN3_URDF_V12.urdf` (the ranges of joints 2, 4
  and 6). Kinova's kortex joint_limits.yaml publishes no acceleration or jerk: None.

`apply_datasheet` (which `[robot] datasheet` calls) combines a datasheet with the URDF's
limits: each position, speed and effort limit is the tighter of the two (robots.limits.tighter),
the source recorded as the one that binds; acceleration and jerk are the datasheet's where it
publishes them (scene.config; else the default rules of robots.limits).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError
from articula.robots.limits import URDF, sheet_source, tighter
from articula.robots.model import RobotModel

__all__ = ["DATASHEETS", "Datasheet", "apply_datasheet", "datasheet", "match_joint_names"]

Limits = tuple[float | None, ...]


@dataclass(frozen=True)
class Datasheet:
    """One arm's published joint limits, one entry per joint, base to tip; None for none.

    Attributes:
        name: the key `[robot] datasheet` takes, e.g. "franka-panda".
        arm: the arm's name as its maker writes it.
        source: the documents the numbers come from.
        lower: lower position limits [rad].
        upper: upper position limits [rad].
        velocity: speed limits [rad/s].
        acceleration: acceleration limits [rad/s²].
        jerk: jerk limits [rad/s³].
        effort: torque limits [N·m].
        joint_names: the URDF joint names that identify this arm alone (its maker's
            description), or () where other arms share them (every UR size has the same).
    """

    name: str
    arm: str
    source: str
    lower: Limits
    upper: Limits
    velocity: Limits
    acceleration: Limits
    jerk: Limits
    effort: Limits
    joint_names: tuple[str, ...] = ()

    @property
    def nq(self) -> int:
        """Number of joints."""
        return len(self.velocity)


_FRANKA = (
    "Franka, Robot and interface specifications "
    "(https://frankaemika.github.io/docs/control_parameters.html)"
)
_PANDA = f"{_FRANKA}, Limits for Panda"
_FR3 = (
    f"{_FRANKA}, Limits for Franka Research 3 (rectangular speed limits); franka_description "
    "robots/fr3/joint_limits.yaml; libfranka include/franka/rate_limiting.h (FR3 releases)"
)
_UR_MANUALS = "https://s3-eu-west-1.amazonaws.com/ur-support-site/"
_UR = (
    "{} User Manual ({}); UR support article Max. joint torques "
    "(https://www.universal-robots.com/articles/ur-articles/max-joint-torques); as in "
    "Universal_Robots_ROS2_Description config/{}/joint_limits.yaml"
)
_KINOVA = (
    "Kinova, github.com/Kinovarobotics/ros2_kortex kortex_description/arms/gen3/7dof/urdf/"
    "gen3_macro.xacro; github.com/Kinovarobotics/ros_kortex kortex_description/arms/gen3/7dof/"
    "urdf/GEN3_URDF_V12.urdf (ranges of joints 2, 4, 6)"
)
_TURN = 2 * math.pi  # [rad] UR's ±360°
_HALF = math.pi  # [rad/s] 180°/s
_THIRD = 2 * math.pi / 3  # [rad/s] 120°/s
_NONE6: Limits = (None,) * 6


def _ur(name: str, arm: str, manual: str, velocity: Limits, effort: Limits) -> Datasheet:
    """A Universal Robots arm: every joint ±360°, no published acceleration or jerk; its
    user manual at UR's support site path `manual`."""
    source = _UR.format(arm, _UR_MANUALS + manual, name)
    return Datasheet(
        name, arm, source, (-_TURN,) * 6, (_TURN,) * 6, velocity, _NONE6, _NONE6, effort
    )


# fmt: off
DATASHEETS: dict[str, Datasheet] = {sheet.name: sheet for sheet in (
    Datasheet(
        "franka-panda", "Franka Emika Panda (FER)", _PANDA,
        lower=(-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
        upper=(2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
        velocity=(2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100),
        acceleration=(15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0),
        jerk=(7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0),
        effort=(87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0),
        joint_names=tuple(f"panda_joint{i}" for i in range(1, 8)),
    ),
    Datasheet(
        "franka-fr3", "Franka Research 3", _FR3,
        lower=(-2.7437, -1.7837, -2.9007, -3.0421, -2.8065, 0.5445, -3.0159),
        upper=(2.7437, 1.7837, 2.9007, -0.1518, 2.8065, 4.5169, 3.0159),
        velocity=(2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26),
        acceleration=(10.0,) * 7,
        jerk=(5000.0,) * 7,
        effort=(87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0),
        joint_names=tuple(f"fr3_joint{i}" for i in range(1, 8)),
    ),
    _ur("ur3e", "Universal Robots UR3e", "69043/99403_UR3e_User_Manual_en_Global.pdf",
        (_HALF, _HALF, _HALF, _TURN, _TURN, _TURN), (56.0, 56.0, 28.0, 12.0, 12.0, 12.0)),
    _ur("ur5e", "Universal Robots UR5e", "69091/99404_UR5e_User_Manual_en_Global.pdf",
        (_HALF,) * 6, (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)),
    _ur("ur10e", "Universal Robots UR10e", "69139/99405_UR10e_User_Manual_en_Global.pdf",
        (_THIRD, _THIRD, _HALF, _HALF, _HALF, _HALF), (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)),
    _ur("ur16e", "Universal Robots UR16e", "69187/99473_UR16e_User_Manual_en_Global.pdf",
        (_THIRD, _THIRD, _HALF, _HALF, _HALF, _HALF), (330.0, 330.0, 150.0, 54.0, 54.0, 54.0)),
    _ur("ur5", "Universal Robots UR5 (CB3)", "69371/99202_UR5_User_Manual_en_Global.pdf",
        (_HALF,) * 6, (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)),
    _ur("ur10", "Universal Robots UR10 (CB3)", "69442/99203_UR10_User_Manual_en_Global.pdf",
        (_THIRD, _THIRD, _HALF, _HALF, _HALF, _HALF), (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)),
    # Ranges of joints 2, 4, 6 from GEN3_URDF_V12.urdf; the Gen3 user guide's own table could
    # not be read to check them, and a later ros2_kortex macro narrows joint 2 to ±1.4 rad
    # without a stated reason. Joints 1, 3, 5, 7 turn without end.
    Datasheet(
        "kinova-gen3", "Kinova Gen3 7-DOF", _KINOVA,
        lower=(None, -2.41, None, -2.66, None, -2.23, None),
        upper=(None, 2.41, None, 2.66, None, 2.23, None),
        velocity=(1.3963, 1.3963, 1.3963, 1.3963, 1.2218, 1.2218, 1.2218),
        acceleration=(None,) * 7,
        jerk=(None,) * 7,
        effort=(39.0, 39.0, 39.0, 39.0, 9.0, 9.0, 9.0),
    ),
)}
# fmt: on


def datasheet(name: str, nq: int, field: str = "datasheet") -> Datasheet:
    """The datasheet called `name`, checked against an arm of nq joints.

    Args:
        name: a key of DATASHEETS, e.g. "franka-panda".
        nq: the arm's number of joints.
        field: the setting `name` came from, named in errors.

    Returns:
        The datasheet.

    Raises:
        ConfigError: an unknown name (the error lists the known ones), or a datasheet for
            another number of joints.
    """
    sheet = DATASHEETS.get(name)
    if sheet is None:
        raise ConfigError(field, f"unknown arm {name!r}; choose one of {sorted(DATASHEETS)}")
    if sheet.nq != nq:
        raise ConfigError(
            field,
            f"{name!r} ({sheet.arm}) has {sheet.nq} joints but the robot has {nq}; choose "
            "the datasheet of this arm, or lock the extra joints with locked_joints",
        )
    return sheet


def match_joint_names(joint_names: Sequence[str]) -> Datasheet | None:
    """The datasheet whose maker's joint names are exactly these, or None (no arm, or names
    that several arms share, as every UR size does).

    Args:
        joint_names: the robot's joint names, base to tip.

    Returns:
        The matching datasheet, or None.
    """
    names = tuple(joint_names)
    found = [s for s in DATASHEETS.values() if s.joint_names and s.joint_names == names]
    return found[0] if len(found) == 1 else None


def apply_datasheet(robot: RobotModel, name: str | None) -> Datasheet | None:
    """Combine a datasheet's position, speed and effort limits into `robot`'s: each becomes
    the tighter of the datasheet's and the URDF's (a continuous joint keeps no position
    limit: its values wrap). Sets robot.datasheet (the name and how it was chosen) and the
    "position", "velocity" and "effort" entries of robot.limit_sources.

    Args:
        robot: the robot loaded from its URDF; changed in place.
        name: a key of DATASHEETS; None: the datasheet the joint names identify
            (`match_joint_names`), if any; "none": no datasheet.

    Returns:
        The datasheet applied, or None.

    Raises:
        ConfigError: (field "datasheet") an unknown name, or a datasheet for another number
            of joints.
    """
    if name == "none":
        return None
    if name is not None:
        sheet = datasheet(name, robot.nq)
        robot.datasheet = f"{sheet.name} ([robot] datasheet)"
    else:
        found = match_joint_names(robot.joint_names)
        if found is None:
            return None
        sheet, names = found, robot.joint_names
        robot.datasheet = f"{sheet.name} (matched by the joint names {names[0]}..{names[-1]})"
    source, model = sheet_source(sheet.name), robot.model
    free = robot.continuous
    # A lower limit is an upper limit of −q: tighter takes the smaller of the negated ones.
    lower = [None if f or v is None else -v for f, v in zip(free, sheet.lower, strict=True)]
    upper = [None if f else v for f, v in zip(free, sheet.upper, strict=True)]
    low, low_from = tighter(-model.lowerPositionLimit, lower, source)
    high, high_from = tighter(model.upperPositionLimit, upper, source)
    model.lowerPositionLimit, model.upperPositionLimit = -low, high
    robot.limit_sources["position"] = tuple(
        source if source in pair else URDF for pair in zip(low_from, high_from, strict=True)
    )
    for key, urdf, published in (
        ("velocity", model.velocityLimit, sheet.velocity),
        ("effort", model.effortLimit, sheet.effort),
    ):
        stated = np.where((urdf > 0) & np.isfinite(urdf), urdf, np.inf)  # ≤ 0 or ∞: none
        values, robot.limit_sources[key] = tighter(stated, published, source)
        # Where neither gives one, the URDF's own way of saying none stays (0 or ∞).
        setattr(model, f"{key}Limit", np.where(np.isfinite(values), values, urdf))
    return sheet
