"""mink (differential IK on MuJoCo) on an articula Scene: the same arm, hulls and obstacles.

    arm = MinkArm(scene, d_min=0.002, detection=0.15)
    q = arm.reset(q0)
    every 10 ms:
        q = arm.step(target_position)          # or arm.step(target, {"rock": pose})

The MuJoCo model is bench/mink_model.py's (build_model): the arm's joints, articula's link
hulls as mesh geoms, a site per link frame and at the end effector, obstacles as mocap
bodies.

One period of the controller is mink's usual loop: a FrameTask on the end-effector site
(position cost 1, orientation cost 0), ConfigurationLimit, VelocityLimit (the URDF's speed
limits), CollisionAvoidanceLimit between every link geom and every obstacle geom, solved by
`mink.solve_ik(..., solver="daqp")` and integrated for dt.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import mink
import mujoco
import numpy as np
import pinocchio as pin

from articula.bench.mink_model import EE_SITE, build_model, link_geom, obstacle_geom
from articula.scene.scene import Scene


def matched_gain(dt: float, d_min: float, detection: float, rate: float = 1.0) -> float:
    """CollisionAvoidanceLimit's gain that makes its bound the qp's velocity damper: mink
    bounds a displacement by gain (d − d_min) / dt, the damper a speed by rate (d − d_min) /
    (detection − d_min) with rate [m/s], so gain = dt² · rate / (detection − d_min).

    Args:
        dt: the control period [s].
        d_min: the minimum distance [m].
        detection: the collision detection distance (articula's influence) [m].
        rate: the damper's speed bound at d = detection [m/s].

    Returns:
        The gain to give MinkArm.
    """
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
        """Start from q [rad] (articula's joint order).

        Args:
            q: the start joint positions in articula's joint order, shape (nq,) [rad].

        Returns:
            The joint positions now held, shape (nq,) [rad].
        """
        qpos = self.configuration.data.qpos.copy()
        qpos[self.qpos_index] = np.asarray(q, dtype=float)
        self.configuration.update(qpos)
        self.infeasible = 0
        return self.q

    def set_obstacle_pose(self, name: str, pose: np.ndarray) -> None:
        """Move obstacle `name` to `pose` (4×4, world).

        Args:
            name: the obstacle's name.
            pose: its homogeneous transform in the world, shape (4, 4) [m].
        """
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
        """One control period toward the target position [m]; returns the new q [rad].

        Args:
            target: the end-effector target position in the world, shape (3,) [m].
            obstacle_poses: new world poses of obstacles by name, each shape (4, 4) [m], or None
                to leave them where they are.

        Returns:
            The joint positions after the period, shape (nq,) [rad]; unchanged when the QP had no
            solution (counted in `infeasible`).
        """
        for name, pose in (obstacle_poses or {}).items():
            self.set_obstacle_pose(name, pose)
        if obstacle_poses:
            self.configuration.update()
        self._target.wxyz_xyz[4:] = target
        self.task.set_target(self._target)
        try:
            v = mink.solve_ik(
                self.configuration,
                [self.task],
                self.dt,
                solver="daqp",
                damping=self.damping,
                limits=self.limits,
            )
        except mink.NoSolutionFound:
            self.infeasible += 1
            return self.q
        self.configuration.integrate_inplace(v, self.dt)
        return self.q

    # ----- what the tests compare with articula --------------------------------------------

    def site_pose(self, name: str) -> np.ndarray:
        """Pose (4×4, world) of a site at the current configuration.

        Args:
            name: the site's name (EE_SITE or link_site(link)).

        Returns:
            The site's homogeneous transform in the world, shape (4, 4) [m].
        """
        data, site = self.configuration.data, self.model.site(name).id
        T = np.eye(4)
        T[:3, :3] = data.site_xmat[site].reshape(3, 3)
        T[:3, 3] = data.site_xpos[site]
        return T

    def ee_position(self) -> np.ndarray:
        """The end-effector site's position [m] at the current configuration.

        Returns:
            The position in the world, shape (3,) [m].
        """
        return self.site_pose(EE_SITE)[:3, 3]

    def geom_vertices(self, name: str) -> np.ndarray:
        """World vertices [m] of mesh geom `name` at the current configuration (MuJoCo keeps
        them in the mesh's own frame, centred and turned onto its principal axes).

        Args:
            name: the mesh geom's name (link_geom or obstacle_geom).

        Returns:
            The mesh's vertices in the world, shape (v, 3) [m].
        """
        data, g = self.configuration.data, self.model.geom(name).id
        mesh = self.model.geom_dataid[g]
        start, count = self.model.mesh_vertadr[mesh], self.model.mesh_vertnum[mesh]
        local = self.model.mesh_vert[start : start + count]
        return data.geom_xpos[g] + local @ data.geom_xmat[g].reshape(3, 3).T

    def hull_vertices(self, name: str) -> np.ndarray:
        """World vertices [m] of the convex hull MuJoCo collides mesh geom `name` with.

        Args:
            name: the mesh geom's name (link_geom or obstacle_geom).

        Returns:
            The hull's vertices in the world, shape (h, 3) [m].
        """
        mesh = self.model.geom_dataid[self.model.geom(name).id]
        graph = self.model.mesh_graph[self.model.mesh_graphadr[mesh] :]
        numvert = graph[0]
        # mesh_graph: numvert, numface, vert_edgeadr[numvert], vert_globalid[numvert], ...
        ids = graph[2 + numvert : 2 + 2 * numvert]
        return self.geom_vertices(name)[ids]

    def distance(self, a: str, b: str, within: float = 1.0) -> float:
        """mj_geomDistance between geoms a and b [m] (capped at `within`).

        Args:
            a: the first geom's name.
            b: the second geom's name.
            within: the largest distance computed [m].

        Returns:
            The signed distance (negative when they penetrate), at most `within` [m].
        """
        fromto = np.empty(6)
        data = self.configuration.data
        return mujoco.mj_geomDistance(
            self.model, data, self.model.geom(a).id, self.model.geom(b).id, within, fromto
        )


def _free_joints(model: pin.Model) -> list[int]:
    """Pinocchio joint ids with a configuration entry, in q order."""
    ids = [j for j in range(1, model.njoints) if model.joints[j].nq == 1]
    return sorted(ids, key=lambda j: model.joints[j].idx_q)
