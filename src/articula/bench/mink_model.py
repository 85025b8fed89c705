"""mink's MuJoCo model of an articula Scene: the same arm, hulls and obstacles.

The MuJoCo model is built with MjSpec from the Pinocchio model `scene.robot.model`: one body
per joint at the joint's placement in its parent joint (a hinge or slide joint on its axis,
the URDF's position limits), so that a body's frame is Pinocchio's joint frame. Each articula
link shape becomes a mesh geom whose vertices are articula's hull vertices, placed at the
link frame's placement times the shape's placement; a site marks every link frame and the
end-effector frame. Each obstacle is a mocap body at its pose (world fixed but not welded to
the world, so mink's CollisionAvoidanceLimit keeps its pairs with every moving link, and a
live pose can be set per period), its convex parts mesh geoms (primitives as MuJoCo's).

MuJoCo stores mesh vertices in float32: a geom's vertices are articula's to about 1e-8 m,
while link frames and the end effector agree to rounding (tests/benchmarks).
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np
import pinocchio as pin

from articula.scene.scene import Scene

EE_SITE = "ee"
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def link_site(name: str) -> str:
    """The site at articula link `name`'s frame.

    Args:
        name: the articula link's name.

    Returns:
        The MuJoCo site's name.
    """
    return f"frame:{name}"


def link_geom(name: str, k: int) -> str:
    """The geom of shape k of articula link `name`.

    Args:
        name: the articula link's name.
        k: the shape's index in the link's shapes.

    Returns:
        The MuJoCo geom's name.
    """
    return f"{name}/{k}"


def obstacle_geom(name: str, k: int) -> str:
    """The geom of part k of obstacle `name`.

    Args:
        name: the obstacle's name.
        k: the part's index in the obstacle's convex parts.

    Returns:
        The MuJoCo geom's name.
    """
    return f"obstacle:{name}/{k}"


def build_model(scene: Scene) -> mujoco.MjModel:
    """The MuJoCo model of `scene`: the arm of scene.robot.model, articula's link hulls as
    mesh geoms, a site per link frame and one at the end effector, obstacles as mocap bodies.

    Args:
        scene: the articula scene; obstacles are placed at their pose at t = 0.

    Returns:
        The compiled MuJoCo model.
    """
    return build_spec(scene).compile()


def build_spec(scene: Scene) -> mujoco.MjSpec:
    """The MjSpec of build_model (see the module's docstring).

    Args:
        scene: the articula scene; obstacles are placed at their pose at t = 0.

    Returns:
        The model's spec, not yet compiled.
    """
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
        body.add_geom(
            name=name,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=list(geometry.halfSide),
            **_pose(placement),
        )
    elif kind == "sphere":
        body.add_geom(
            name=name,
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[geometry.radius, 0.0, 0.0],
            **_pose(placement),
        )
    elif kind in ("cylinder", "capsule"):
        kind_of = {
            "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
            "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
        }
        body.add_geom(
            name=name,
            type=kind_of[kind],
            size=[geometry.radius, geometry.halfLength, 0.0],
            **_pose(placement),
        )
    else:  # a convex hull: its vertices; MuJoCo takes their convex hull for collisions
        spec.add_mesh(name=f"mesh:{name}", uservert=np.asarray(shape.vertices).ravel().tolist())
        body.add_geom(
            name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"mesh:{name}", **_pose(placement)
        )
