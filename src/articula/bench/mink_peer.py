"""mink (differential IK on MuJoCo) on an articula Scene: the same arm, hulls and obstacles.

    arm = MinkArm(scene, d_min=0.002, detection=0.15)
    q = arm.reset(q0)
    every 10 ms:
        q = arm.step(target_position)          # or arm.step(target, {"rock": pose})

The MuJoCo model is built with MjSpec from the Pinocchio model `scene.robot.model`: one body
per joint at the joint's placement in its parent joint (a hinge or slide joint on its axis,
the URDF's position limits), so that a body's frame is Pinocchio's joint frame. Each articula
link shape becomes a mesh geom whose vertices are articula's hull vertices, placed at the
link frame's placement times the shape's placement; a site marks every link frame and the
end-effector frame. Each obstacle is a mocap body at its pose (world fixed but not welded to
the world, so mink's CollisionAvoidanceLimit keeps its pairs with every moving link, and a
live pose can be set per period), its convex parts mesh geoms (primitives as MuJoCo's).

One period of the controller is mink's usual loop: a FrameTask on the end-effector site
(position cost 1, orientation cost 0), ConfigurationLimit, VelocityLimit (the URDF's speed
limits), CollisionAvoidanceLimit between every link geom and every obstacle geom, solved by
`mink.solve_ik(..., solver="daqp")` and integrated for dt.

MuJoCo stores mesh vertices in float32: a geom's vertices are articula's to about 1e-8 m,
while link frames and the end effector agree to rounding (tests/benchmarks).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import mink
import mujoco
import numpy as np
import pinocchio as pin

from articula.scene.scene import Scene

EE_SITE = "ee"
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def link_site(name: str) -> str:
    """The site at articula link `name`'s frame."""
    return f"frame:{name}"


def link_geom(name: str, k: int) -> str:
    """The geom of shape k of articula link `name`."""
    return f"{name}/{k}"


def obstacle_geom(name: str, k: int) -> str:
    """The geom of part k of obstacle `name`."""
    return f"obstacle:{name}/{k}"


def build_model(scene: Scene) -> mujoco.MjModel:
    """The MuJoCo model of `scene`: the arm of scene.robot.model, articula's link hulls as
    mesh geoms, a site per link frame and one at the end effector, obstacles as mocap bodies."""
    return build_spec(scene).compile()


def build_spec(scene: Scene) -> mujoco.MjSpec:
    """The MjSpec of build_model (see the module's docstring)."""
    robot, model = scene.robot, scene.robot.model
    spec = mujoco.MjSpec()
    spec.modelname = "articula_peer"
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    bodies = {0: spec.worldbody}
    for j in range(1, model.njoints):
        joint = model.joints[j]
        kind, axis = _joint_kind(joint.shortname(), joint)
        body = bodies[model.parents[j]].add_body(
            name=f"joint_body:{model.names[j]}", **_pose(model.jointPlacements[j])
        )
        # A fixed inertia: MuJoCo needs one on every moving body and kinematics ignore it.
        body.explicitinertial = True
        body.mass = 1.0
        body.inertia = [1e-3, 1e-3, 1e-3]
        i = joint.idx_q
        body.add_joint(
            name=model.names[j],
            type=kind,
            axis=axis,
            range=[model.lowerPositionLimit[i], model.upperPositionLimit[i]],
        )
        bodies[j] = body
    for link in robot.links:
        frame = model.frames[link.frame_id]
        body = bodies[frame.parentJoint]
        body.add_site(name=link_site(link.name), **_pose(frame.placement))
        for k, (shape, T) in enumerate(zip(link.shapes, link.placements, strict=True)):
            name = link_geom(link.name, k)
            _add_shape(spec, body, name, shape, frame.placement * pin.SE3(T))
    ee = model.frames[robot.ee_frame_id]
    bodies[ee.parentJoint].add_site(name=EE_SITE, **_pose(ee.placement))
    for obstacle in scene.obstacles:
        body = spec.worldbody.add_body(
            name=f"obstacle:{obstacle.name}", mocap=True, **_pose(pin.SE3(obstacle.pose_at(0.0)))
        )
        for k, part in enumerate(obstacle.parts):
            _add_shape(spec, body, obstacle_geom(obstacle.name, k), part, pin.SE3.Identity())
    return spec


def _joint_kind(shortname: str, joint: pin.JointModel) -> tuple[int, Sequence[float]]:
    """(MuJoCo joint type, axis) of a Pinocchio 1-DoF joint."""
    if shortname.startswith("JointModelR") and shortname[-1] in _AXES:
        return mujoco.mjtJoint.mjJNT_HINGE, _AXES[shortname[-1]]
    if shortname.startswith("JointModelP") and shortname[-1] in _AXES:
        return mujoco.mjtJoint.mjJNT_SLIDE, _AXES[shortname[-1]]
    if shortname == "JointModelRevoluteUnaligned":
        return mujoco.mjtJoint.mjJNT_HINGE, list(joint.extract().axis)
    if shortname == "JointModelPrismaticUnaligned":
        return mujoco.mjtJoint.mjJNT_SLIDE, list(joint.extract().axis)
    raise ValueError(f"joint model {shortname} has no MuJoCo peer here (mimic joints neither)")


def _pose(placement: pin.SE3) -> dict[str, list[float]]:
    """pos and quat (w, x, y, z) keyword arguments of a Pinocchio placement."""
    x, y, z, w = pin.Quaternion(placement.rotation).coeffs()
    return {"pos": list(placement.translation), "quat": [w, x, y, z]}


def _add_shape(spec, body, name: str, shape, placement: pin.SE3) -> None:
    """A geom for an articula ConvexShape at `placement` in `body`: a mesh of its hull
    vertices, or MuJoCo's own primitive."""
    geometry = shape.geometry
    kind = shape.kind
    if kind == "box":
        body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX,
                      size=list(geometry.halfSide), **_pose(placement))  # fmt: skip
    elif kind == "sphere":
        body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_SPHERE,
                      size=[geometry.radius, 0.0, 0.0], **_pose(placement))  # fmt: skip
    elif kind in ("cylinder", "capsule"):
        kind_of = {"cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
                   "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE}  # fmt: skip
        body.add_geom(name=name, type=kind_of[kind],
                      size=[geometry.radius, geometry.halfLength, 0.0],
                      **_pose(placement))  # fmt: skip
    else:  # a convex hull: its vertices; MuJoCo takes their convex hull for collisions
        spec.add_mesh(name=f"mesh:{name}", uservert=np.asarray(shape.vertices).ravel().tolist())
        body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"mesh:{name}",
                      **_pose(placement))  # fmt: skip


def matched_gain(dt: float, d_min: float, detection: float, rate: float = 1.0) -> float:
    """CollisionAvoidanceLimit's gain that makes its bound the qp's velocity damper: mink
    bounds a displacement by gain (d − d_min) / dt, the damper a speed by rate (d − d_min) /
    (detection − d_min) with rate [m/s], so gain = dt² · rate / (detection − d_min)."""
    return dt**2 * rate / (detection - d_min)


class MinkArm:
    """mink's differential IK on the arm of an articula Scene, one control period per step.

    Args:
        scene: the articula scene (robot, obstacles at their pose at t = 0).
        d_min: CollisionAvoidanceLimit's minimum_distance_from_collisions [m].
        detection: its collision_detection_distance [m] (articula's influence).
        dt: the control period [s].
        velocity_scale: fraction of the URDF joint speed limits.
        damping: solve_ik's Levenberg-Marquardt damping (mink's default).
        gain: CollisionAvoidanceLimit's gain (mink's default). mink bounds the approach of a
            pair in one period, a displacement, by gain (d − d_min) / dt: the default 0.85
            binds only once d ≤ d_min at dt = 0.01 s; gain = rate [1/s] · dt² makes it a
            damper of that rate (matched_gain).
    """

    def __init__(
        self,
        scene: Scene,
        d_min: float,
        detection: float,
        dt: float = 0.01,
        velocity_scale: float = 1.0,
        damping: float = 1e-12,
        gain: float = 0.85,
    ) -> None:
        self.scene = scene
        self.dt = dt
        self.damping = damping
        self.model = build_model(scene)
        self.configuration = mink.Configuration(self.model)
        robot, model = scene.robot, scene.robot.model
        # articula q index -> MuJoCo qpos address (the same order for a serial chain).
        self.qpos_index = np.array(
            [self.model.joint(model.names[j]).qposadr[0] for j in _free_joints(model)]
        )
        self.task = mink.FrameTask(EE_SITE, "site", position_cost=1.0, orientation_cost=0.0)
        speeds = {
            model.names[j]: velocity_scale * robot.velocity_limit[model.joints[j].idx_v]
            for j in _free_joints(model)
            if np.isfinite(robot.velocity_limit[model.joints[j].idx_v])
            and robot.velocity_limit[model.joints[j].idx_v] > 0
        }
        self.link_geoms = [
            link_geom(link.name, k) for link in robot.links for k in range(len(link.shapes))
        ]
        self.obstacle_geoms = [
            obstacle_geom(o.name, k) for o in scene.obstacles for k in range(len(o.parts))
        ]
        self.limits: list[mink.Limit] = [
            mink.ConfigurationLimit(self.model),
            mink.VelocityLimit(self.model, speeds),
        ]
        self.collision: mink.CollisionAvoidanceLimit | None = None
        if self.obstacle_geoms:
            self.collision = mink.CollisionAvoidanceLimit(
                self.model,
                [(self.link_geoms, self.obstacle_geoms)],
                gain=gain,
                minimum_distance_from_collisions=d_min,
                collision_detection_distance=detection,
            )
            self.limits.append(self.collision)
        self.infeasible = 0  # periods whose QP had no solution (the arm then holds still)
        self._target = mink.SE3.identity()

    @property
    def q(self) -> np.ndarray:
        """The configuration in articula's joint order [rad]."""
        return self.configuration.data.qpos[self.qpos_index].copy()

    def reset(self, q: Sequence[float] | np.ndarray) -> np.ndarray:
        """Start from q [rad] (articula's joint order)."""
        qpos = self.configuration.data.qpos.copy()
        qpos[self.qpos_index] = np.asarray(q, dtype=float)
        self.configuration.update(qpos)
        self.infeasible = 0
        return self.q

    def set_obstacle_pose(self, name: str, pose: np.ndarray) -> None:
        """Move obstacle `name` to `pose` (4×4, world)."""
        body = self.model.body(f"obstacle:{name}")
        mocap = self.model.body_mocapid[body.id]
        data = self.configuration.data
        data.mocap_pos[mocap] = pose[:3, 3]
        x, y, z, w = pin.Quaternion(np.asarray(pose[:3, :3])).coeffs()
        data.mocap_quat[mocap] = [w, x, y, z]

    def step(
        self,
        target: Sequence[float] | np.ndarray,
        obstacle_poses: Mapping[str, np.ndarray] | None = None,
    ) -> np.ndarray:
        """One control period toward the target position [m]; returns the new q [rad]."""
        for name, pose in (obstacle_poses or {}).items():
            self.set_obstacle_pose(name, pose)
        if obstacle_poses:
            self.configuration.update()
        self._target.wxyz_xyz[4:] = target
        self.task.set_target(self._target)
        try:
            v = mink.solve_ik(self.configuration, [self.task], self.dt, solver="daqp",
                              damping=self.damping, limits=self.limits)  # fmt: skip
        except mink.NoSolutionFound:
            self.infeasible += 1
            return self.q
        self.configuration.integrate_inplace(v, self.dt)
        return self.q

    # ----- what the tests compare with articula --------------------------------------------

    def site_pose(self, name: str) -> np.ndarray:
        """Pose (4×4, world) of a site at the current configuration."""
        data, site = self.configuration.data, self.model.site(name).id
        T = np.eye(4)
        T[:3, :3] = data.site_xmat[site].reshape(3, 3)
        T[:3, 3] = data.site_xpos[site]
        return T

    def ee_position(self) -> np.ndarray:
        """The end-effector site's position [m] at the current configuration."""
        return self.site_pose(EE_SITE)[:3, 3]

    def geom_vertices(self, name: str) -> np.ndarray:
        """World vertices [m] of mesh geom `name` at the current configuration (MuJoCo keeps
        them in the mesh's own frame, centred and turned onto its principal axes)."""
        data, g = self.configuration.data, self.model.geom(name).id
        mesh = self.model.geom_dataid[g]
        start, count = self.model.mesh_vertadr[mesh], self.model.mesh_vertnum[mesh]
        local = self.model.mesh_vert[start : start + count]
        return data.geom_xpos[g] + local @ data.geom_xmat[g].reshape(3, 3).T

    def hull_vertices(self, name: str) -> np.ndarray:
        """World vertices [m] of the convex hull MuJoCo collides mesh geom `name` with."""
        mesh = self.model.geom_dataid[self.model.geom(name).id]
        graph = self.model.mesh_graph[self.model.mesh_graphadr[mesh] :]
        numvert = graph[0]
        # mesh_graph: numvert, numface, vert_edgeadr[numvert], vert_globalid[numvert], ...
        ids = graph[2 + numvert : 2 + 2 * numvert]
        return self.geom_vertices(name)[ids]

    def distance(self, a: str, b: str, within: float = 1.0) -> float:
        """mj_geomDistance between geoms a and b [m] (capped at `within`)."""
        fromto = np.empty(6)
        data = self.configuration.data
        return mujoco.mj_geomDistance(
            self.model, data, self.model.geom(a).id, self.model.geom(b).id, within, fromto
        )


def _free_joints(model: pin.Model) -> list[int]:
    """Pinocchio joint ids with a configuration entry, in q order."""
    ids = [j for j in range(1, model.njoints) if model.joints[j].nq == 1]
    return sorted(ids, key=lambda j: model.joints[j].idx_q)
