"""How far a joint's motion can move the links beyond it: a bound per joint, for the planners'
braking checks (a motion Δq moves no point of the arm farther than Σ_j sweep_j |Δq_j|)."""

from __future__ import annotations

import numpy as np

from articula.robots.model import RobotModel


def joint_sweep(robot: RobotModel) -> np.ndarray:
    """Per joint, the largest distance [m] a point of a link beyond it moves per unit of the
    joint's motion: for a revolute joint the farthest such point from its origin (the joint
    offsets down the chain plus the link's extent), for a prismatic joint 1; the largest bound
    for every joint when the arm has mimic joints (their motion follows another's).

    Args:
        robot: the arm (a serial chain).

    Returns:
        The bounds, shape (nq,) [m/rad, or m/m for a prismatic joint].
    """
    model = robot.model
    kinds = [joint.shortname() for joint in model.joints]
    extents = np.zeros(model.njoints)  # farthest shape point from each joint's origin [m]
    for link in robot.links:
        frame = model.frames[link.frame_id]
        for shape, placement in zip(link.shapes, link.placements, strict=True):
            pose = frame.placement.homogeneous @ placement @ shape.bound.pose
            far = np.linalg.norm(pose[:3, 3]) + 0.5 * shape.bound.length + shape.bound.radius
            extents[frame.parentJoint] = max(extents[frame.parentJoint], far)
    # Back up the chain: a joint reaches what its child reaches plus the child's offset.
    reach = extents.copy()
    for j in range(model.njoints - 1, 0, -1):
        parent = model.parents[j]
        offset = float(np.linalg.norm(model.jointPlacements[j].translation))
        if kinds[j].startswith("JointModelP") and model.joints[j].nq == 1:
            i = model.joints[j].idx_q  # a prismatic joint moves its child by up to its limit
            offset += max(abs(model.lowerPositionLimit[i]), abs(model.upperPositionLimit[i]))
        reach[parent] = max(reach[parent], reach[j] + offset)
    sweep = np.zeros(robot.nq)
    for j in range(1, model.njoints):
        if model.joints[j].nq == 1:
            prismatic = kinds[j].startswith("JointModelP")
            sweep[model.joints[j].idx_q] = 1.0 if prismatic else reach[j]
    if any(kind == "JointModelMimic" for kind in kinds):
        sweep[:] = max(float(sweep.max()), 1.0)
    return sweep
