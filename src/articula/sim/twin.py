"""The dynamics twin: the arm under rigid-body dynamics (MuJoCo), driven tick by tick by a
servo stream, with its own joint servos, torque limits and contact detection.

The MuJoCo model is built from articula's own model of the arm (the Pinocchio model of the
URDF, locked and mimic joints already resolved, and the same collision shapes), so it is the
arm the planner plans for: one body per revolute joint at the URDF's joint placement, its
links' shapes as geoms (polytopes as meshes, the round primitives as themselves), the
obstacles as static geoms. Each body's inertia is the URDF's `<inertial>` where it gives one,
else that of its collision geometry at DENSITY (the packaged iiwa14 URDF has none: stated in
docs/guides/servo.md). Each joint has a servo: τ = kp (q_ref − q) + kv (q̇_ref − q̇), plus
gravity compensation, all within the URDF's effort limit; the implicit integrator steps at the
servo rate. MuJoCo's own collision detection counts contacts between the arm and the
obstacles and between the link pairs articula checks (the others, neighbours that overlap by
design, are excluded as articula excludes them).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import pinocchio as pin

from articula.errors import ConfigError, ModelError
from articula.geometry.shapes import ConvexShape
from articula.scene.scene import Scene

__all__ = ["DENSITY", "ServoGains", "Twin"]

DENSITY = 1000.0  # [kg/m³] of a link whose URDF states no inertia (MuJoCo's default)
_REVOLUTE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned")


@dataclass(frozen=True)
class ServoGains:
    """A joint servo's gains, as multiples of the joint's effort limit.

    Attributes:
        stiffness: kp / effort [1/rad]: the error at which the servo gives its full effort.
        damping: kv / kp [s]: the servo's velocity-error weight relative to its stiffness.
    """

    stiffness: float = 100.0
    damping: float = 0.05


class Twin:
    """The arm of a scene under rigid-body dynamics.

    Args:
        scene: the robot and its obstacles (moving ones placed by `place_obstacles`).
        rate: the servo rate [Hz]: one `step` per tick.
        gains: the joint servos' gains.

    Attributes:
        model: the MuJoCo model.
        data: the MuJoCo state.
        effort: each joint's effort limit, shape (n,) [N·m].
        kp: each servo's stiffness, shape (n,) [N·m/rad].
        kv: each servo's damping, shape (n,) [N·m·s/rad].
    """

    def __init__(self, scene: Scene, rate: float, gains: ServoGains | None = None) -> None:
        gains = gains or ServoGains()
        robot = scene.robot
        self.effort = np.asarray(robot.model.effortLimit, dtype=float)
        if not np.all(np.isfinite(self.effort) & (self.effort > 0)):
            raise ConfigError("robot.urdf", "the twin needs an effort limit > 0 for every joint")
        if not (np.isfinite(rate) and rate > 0):
            raise ConfigError("servo.rate", f"must be finite and > 0 Hz (got {rate})")
        self.kp = gains.stiffness * self.effort
        self.kv = gains.damping * self.kp
        spec = _arm_spec(scene, self.kp, self.kv)
        spec.option.timestep = 1.0 / rate
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self._moving = [
            (int(self.model.body(f"moving_{oi}").mocapid[0]), obstacle)
            for oi, obstacle in enumerate(scene.obstacles)
            if obstacle.moving
        ]

    @property
    def q(self) -> np.ndarray:
        """The measured joint positions [rad], shape (n,)."""
        return self.data.qpos.copy()

    @property
    def torque(self) -> np.ndarray:
        """The servos' last joint torques [N·m] (gravity compensation included), shape (n,)."""
        return self.data.qfrc_actuator.copy()

    def reset(self, q: np.ndarray) -> None:
        """Put the arm at rest at q [rad].

        Args:
            q: joint positions, shape (n,) [rad].
        """
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = q
        mujoco.mj_forward(self.model, self.data)

    def step(self, q_ref: np.ndarray, qd_ref: np.ndarray) -> None:
        """One servo tick toward the commanded position and velocity.

        Args:
            q_ref: commanded joint positions, shape (n,) [rad].
            qd_ref: commanded joint velocities, shape (n,) [rad/s].
        """
        n = self.effort.size
        self.data.ctrl[:n] = q_ref
        self.data.ctrl[n:] = qd_ref
        mujoco.mj_step(self.model, self.data)

    def place_obstacles(self, t: float) -> None:
        """Put the moving obstacles at their poses of time t [s].

        Args:
            t: time [s].
        """
        for mocap, obstacle in self._moving:
            T = obstacle.pose_at(t)
            self.data.mocap_pos[mocap] = T[:3, 3]
            self.data.mocap_quat[mocap] = _quat(T[:3, :3])

    def contacts(self) -> int:
        """MuJoCo's contacts now (arm–obstacle and checked link pairs).

        Returns:
            How many contacts MuJoCo finds.
        """
        return int(self.data.ncon)


def _arm_spec(scene: Scene, kp: np.ndarray, kv: np.ndarray) -> mujoco.MjSpec:
    """The MuJoCo spec of a scene: the arm's bodies, joints, shapes and servos (gains kp, kv
    per joint), the obstacles."""
    robot = scene.robot
    model = robot.model
    spec = mujoco.MjSpec()
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_AUTO
    spec.compiler.degree = False  # joint ranges in radians, as the URDF's
    bodies = [spec.worldbody]
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.shortname() not in _REVOLUTE:
            raise ModelError(f"the twin takes revolute joints only ({model.names[j]} is not)")
        placement = model.jointPlacements[j]
        body = bodies[model.parents[j]].add_body(
            name=model.names[j], pos=placement.translation, quat=_quat(placement.rotation)
        )
        body.gravcomp = 1.0
        inertia = model.inertias[j]
        if inertia.mass > 0:
            body.explicitinertial = True
            body.mass, body.ipos = inertia.mass, inertia.lever
            body.fullinertia = _six(inertia.inertia)
        hinge = body.add_joint(
            name=model.names[j], type=mujoco.mjtJoint.mjJNT_HINGE, axis=_axis(joint)
        )
        free = robot.continuous[model.idx_qs[j]]
        hinge.limited = (
            mujoco.mjtLimited.mjLIMITED_FALSE if free else mujoco.mjtLimited.mjLIMITED_TRUE
        )
        hinge.range = [model.lowerPositionLimit[j - 1], model.upperPositionLimit[j - 1]]
        hinge.actgravcomp = True
        effort = float(model.effortLimit[j - 1])
        hinge.actfrclimited = mujoco.mjtLimited.mjLIMITED_TRUE
        hinge.actfrcrange = [-effort, effort]
        bodies.append(body)
    # Each servo as a position actuator (kp) and a velocity actuator (kv), so that the
    # implicit integrator takes both gains implicitly: a stiff servo on a light wrist link
    # stays stable at the servo rate. The joint's actuator force (gravity compensation too)
    # is clamped to its effort limit.
    for kind, gains in (("position", kp), ("velocity", kv)):
        for j in range(1, model.njoints):
            servo = spec.add_actuator(name=f"{kind}_{model.names[j]}", target=model.names[j])
            servo.trntype = mujoco.mjtTrn.mjTRN_JOINT
            if kind == "position":
                servo.set_to_position(kp=float(gains[j - 1]))
            else:
                servo.set_to_velocity(kv=float(gains[j - 1]))
    owner = []
    for link in robot.links:
        frame = model.frames[link.frame_id]
        for k, (shape, T) in enumerate(zip(link.shapes, link.placements, strict=True)):
            pose = frame.placement * pin.SE3(T)
            _add_shape(spec, bodies[frame.parentJoint], f"{link.name}_{k}", shape, pose.homogeneous)
        owner.append(frame.parentJoint)
    # The obstacles in bodies of their own (the world body holds the links no joint moves, and
    # its unchecked pairs with the arm are excluded below): a still one fixed, a moving one a
    # mocap body that Twin.place_obstacles moves.
    still = spec.worldbody.add_body(name="obstacles")
    for oi, obstacle in enumerate(scene.obstacles):
        body, pose = still, obstacle.pose_at(0.0)
        if obstacle.moving:
            body = spec.worldbody.add_body(name=f"moving_{oi}", mocap=True)
            body.pos, body.quat, pose = pose[:3, 3], _quat(pose[:3, :3]), np.eye(4)
        for k, part in enumerate(obstacle.parts):
            _add_shape(spec, body, f"obstacle_{oi}_{k}", part, pose)
    checked = {frozenset((owner[a], owner[b])) for a, b in scene.self_pairs}
    names = ["world", *model.names[1:]]
    for a in range(model.njoints):
        for b in range(a + 1, model.njoints):
            if frozenset((a, b)) not in checked:
                spec.add_exclude(bodyname1=names[a], bodyname2=names[b])
    return spec


def _add_shape(
    spec: mujoco.MjSpec, body: mujoco.MjsBody, name: str, shape: ConvexShape, T: np.ndarray
) -> None:
    """A collision shape as a geom of `body` at pose T (4×4, in the body frame)."""
    g = shape.geometry
    pose = {"pos": T[:3, 3], "quat": _quat(T[:3, :3])}
    if shape.kind == "sphere":
        body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[g.radius, 0, 0], **pose)
    elif shape.kind in ("capsule", "cylinder"):
        kind = (
            mujoco.mjtGeom.mjGEOM_CAPSULE
            if shape.kind == "capsule"
            else mujoco.mjtGeom.mjGEOM_CYLINDER
        )
        body.add_geom(name=name, type=kind, size=[g.radius, g.halfLength, 0], **pose)
    else:
        spec.add_mesh(name=name, uservert=np.asarray(shape.vertices, dtype=float).ravel())
        body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=name, **pose)


def _axis(joint: pin.JointModel) -> np.ndarray:
    """A revolute joint's axis in its own frame."""
    name = joint.shortname()
    if name == "JointModelRevoluteUnaligned":
        return np.asarray(joint.extract().axis, dtype=float)
    return np.eye(3)["XYZ".index(name[-1])]


def _quat(rotation: np.ndarray) -> np.ndarray:
    """A rotation matrix as MuJoCo's quaternion (w, x, y, z)."""
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(rotation, dtype=float).ravel())
    return q


def _six(inertia: np.ndarray) -> list[float]:
    """A 3×3 inertia matrix as MuJoCo's fullinertia (ixx, iyy, izz, ixy, ixz, iyz)."""
    i = np.asarray(inertia)
    return [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]
