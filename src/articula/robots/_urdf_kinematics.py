"""The kinematic model of a URDF, as RobotModel builds it: size and sanity checks, continuous
joints as bounded revolute ones, locked joints and a tool frame."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from articula.errors import ConfigError, ModelError
from articula.limits import MAX_ANGLE, MAX_LENGTH

# Limits [rad] given to a continuous joint, read as a revolute one so that it keeps one
# configuration entry (Pinocchio's unbounded joints use two, cos and sin). RobotModel wraps the
# joint's values to (−π, π], so these never bind: the joint has no position limit.
CONTINUOUS_LIMIT = 2 * np.pi


def _check_size(urdf: Path, max_links: int) -> None:
    """ModelError for a URDF with more than `max_links` links, before Pinocchio reads it."""
    try:
        links = sum(1 for _, element in ET.iterparse(urdf) if element.tag == "link")
    except (ET.ParseError, OSError) as exc:
        raise ModelError(f"{urdf}: cannot read URDF ({exc})") from None
    if links > max_links:
        raise ConfigError(
            "urdf",
            f"{urdf} has {links} links, more than the limit of {max_links}; raise it with "
            f"max_links = {links} in [robot]",
        )


def _check_magnitudes(model: pin.Model, urdf: Path) -> None:
    """ModelError for joint origins or limits no arm has (NaN, inf, beyond the stated limits)."""
    for name, placement in zip(model.names[1:], model.jointPlacements[1:], strict=True):
        if not np.all(np.abs(placement.translation) <= MAX_LENGTH):
            raise ModelError(f"{urdf}: joint {name!r} has its origin beyond ±{MAX_LENGTH:g} m")
    limits = np.concatenate([model.lowerPositionLimit, model.upperPositionLimit])
    if not np.all(np.abs(limits) <= MAX_ANGLE):
        raise ModelError(f"{urdf}: joint limits must be finite and within ±{MAX_ANGLE:g}")


def _check_serial(model: pin.Model, urdf: Path) -> None:
    """Only 1-DoF joints (revolute, prismatic) are supported, one per configuration entry, and
    mimic joints that follow one of them."""
    for joint, name in zip(model.joints[1:], model.names[1:], strict=True):
        if joint.shortname() == "JointModelMimic":
            continue
        if joint.nq != 1 or joint.nv != 1:
            raise ModelError(
                f"{urdf}: joint {name!r} ({joint.shortname()}) is not a 1-DoF revolute, "
                "continuous or prismatic joint"
            )


def _prepare_urdf(
    urdf: Path,
) -> tuple[str, list[tuple[str, str]], dict[str, str], list[str]]:
    """(URDF text with every continuous joint made revolute within ±CONTINUOUS_LIMIT, the
    (joint, "velocity" | "effort") limits it lacked, mimic joint -> the joint it follows, the
    continuous joints' names)."""
    try:
        root = ET.parse(urdf).getroot()
    except (ET.ParseError, OSError) as exc:
        raise ModelError(f"{urdf}: cannot read URDF ({exc})") from None
    unlimited = []
    mimics = {}
    continuous = []
    for joint in root.iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None:
            mimics[joint.get("name", "")] = mimic.get("joint", "")
        if joint.get("type") != "continuous":
            continue
        continuous.append(joint.get("name", ""))
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit")
        limit.set("lower", repr(-CONTINUOUS_LIMIT))
        limit.set("upper", repr(CONTINUOUS_LIMIT))
        for key in ("velocity", "effort"):
            if limit.get(key) is None:
                # urdfdom needs both for a revolute joint; _unbounded restores a missing one
                # as ∞, what Pinocchio gives a continuous joint without it.
                unlimited.append((joint.get("name", ""), key))
                limit.set(key, "0")
    return ET.tostring(root, encoding="unicode"), unlimited, mimics, continuous


def _unbounded(model: pin.Model, missing: Sequence[tuple[str, str]]) -> None:
    """Set the named (joint, "velocity" | "effort") limits to ∞ (the URDF gave none)."""
    limits = {"velocity": model.velocityLimit.copy(), "effort": model.effortLimit.copy()}
    for name, key in missing:
        limits[key][model.joints[model.getJointId(name)].idx_v] = np.inf
    model.velocityLimit, model.effortLimit = limits["velocity"], limits["effort"]


def _lock(model: pin.Model, values: dict[str, float], mimics: Mapping[str, str]) -> pin.Model:
    """The reduced model with the named joints fixed at their values [rad or m]; the other
    joints' reference is neutral (it does not matter: their frames keep their placements)."""
    q_reference = pin.neutral(model)
    ids = []
    for name, value in values.items():
        field = f"locked_joints.{name}"
        if not model.existJointName(name):
            free = [n for n, j in zip(model.names[1:], model.joints[1:], strict=True) if j.nq]
            raise ConfigError(field, f"no joint {name!r}; the joints are {free}")
        if name in mimics:
            raise ConfigError(
                field, f"{name!r} mimics {mimics[name]!r}; lock {mimics[name]!r} instead"
            )
        joint_id = model.getJointId(name)
        index = model.joints[joint_id].idx_q
        low, high = model.lowerPositionLimit[index], model.upperPositionLimit[index]
        if not low <= value <= high:
            raise ConfigError(field, f"{value!r} is outside the joint's limits [{low:g}, {high:g}]")
        q_reference[index] = value
        ids.append(joint_id)
        # A mimic joint of a locked joint is locked with it, at the value it follows.
        ids += [model.getJointId(m) for m, followed in mimics.items() if followed == name]
    if len(ids) - sum(1 for j in ids if model.joints[j].nq == 0) >= model.nq:
        raise ConfigError("locked_joints", "locks every joint; leave at least one free")
    return pin.buildReducedModel(model, sorted(set(ids)), q_reference)


def _add_tool_frame(model: pin.Model, ee_frame: str, offset: np.ndarray) -> str:
    """Add the frame at pose `offset` (4×4, [m]) in frame `ee_frame` and return its name."""
    T = np.asarray(offset, dtype=float)
    if T.shape != (4, 4):
        raise ConfigError("ee_offset", f"needs a 4×4 pose (got shape {T.shape})")
    R, p = T[:3, :3], T[:3, 3]
    if not (
        np.all(np.abs(p) <= MAX_LENGTH)
        and np.allclose(R @ R.T, np.eye(3), atol=1e-9)
        and np.linalg.det(R) > 0
        and np.array_equal(T[3], [0.0, 0.0, 0.0, 1.0])
    ):
        raise ConfigError(
            "ee_offset",
            f"needs a rigid pose: a rotation and a translation within ±{MAX_LENGTH:g} m "
            f"(got {T.tolist()})",
        )
    if not model.existFrame(ee_frame):
        names = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
        raise ConfigError("ee_frame", f"no frame {ee_frame!r}; the links are {names}")
    name = f"{ee_frame}_offset"
    if model.existFrame(name):
        raise ConfigError("ee_offset", f"the URDF already has a frame {name!r}")
    parent_id = model.getFrameId(ee_frame)
    parent = model.frames[parent_id]
    placement = parent.placement * pin.SE3(R.copy(), p.copy())
    model.addFrame(
        pin.Frame(name, parent.parentJoint, parent_id, placement, pin.FrameType.OP_FRAME)
    )
    return name
