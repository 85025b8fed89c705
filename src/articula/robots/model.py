"""RobotModel: forward kinematics, limits, Jacobians and link collision shapes of a serial arm."""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin

from articula.errors import ConfigError, ModelError
from articula.geometry.shapes import ConvexShape
from articula.limits import MAX_ANGLE, MAX_LINKS
from articula.native import captured_output
from articula.robots._urdf_kinematics import (
    _add_tool_frame,
    _check_magnitudes,
    _check_serial,
    _check_size,
    _lock,
    _prepare_urdf,
    _unbounded,
)
from articula.robots.limits import ACCEL_TIME, JERK_TIME, default_sources, rise_limit
from articula.robots.urdf_geometry import collision_shapes

BUILTIN = {
    "iiwa14": ("iiwa14/iiwa14.urdf", "iiwa_link_ee"),
    "ur5e": ("ur5e/ur5e.urdf", "tool0"),
}


@dataclass(frozen=True, eq=False)
class LinkGeometry:
    """A link's collision shapes and their poses in the link frame.

    Attributes:
        name: the link's name in the URDF.
        frame_id: index of the link's body frame in the Pinocchio model.
        shapes: the link's convex collision shapes.
        placements: pose of each shape in the link frame, each shape (4, 4) [m].
    """

    name: str
    frame_id: int
    shapes: tuple[ConvexShape, ...]
    placements: tuple[np.ndarray, ...]


class RobotModel:
    """A serial arm of 1-DoF revolute or prismatic joints, loaded from a URDF.

    Mimic joints (URDF <mimic>) have no configuration entry of their own: they follow the
    joint they mimic, q_mimic = multiplier · q_joint + offset, in every kinematic quantity.

    Continuous joints have no position limit: their values wrap to (−π, π] (`wrap`) and their
    motion is taken the shortest way round (`difference`).

    Args:
        model: the Pinocchio kinematic model.
        links: the collision shapes of the links, in frame order.
        ee_frame: name of the end-effector frame.
        continuous: names of the continuous joints (unknown names, such as locked joints, are
            ignored).

    Attributes:
        continuous: True for each continuous joint, shape (nq,).
        acceleration_limit: joint acceleration limits [rad/s² or m/s²], inf for none; by
            default each URDF speed limit reached from rest in ACCEL_TIME (robots.limits;
            scene files set it from [robot] acceleration_limits or accel_time).
        jerk_limit: joint jerk limits [rad/s³ or m/s³], inf for none; by default each
            acceleration limit reached from zero in JERK_TIME (scene files set it from
            [robot] jerk_limits or jerk_time).
        limit_sources: where each joint limit came from, one source per joint for each of
            "position", "velocity", "acceleration", "jerk", "effort" (robots.limits).
        datasheet: the maker's datasheet whose limits were combined with the URDF's, and
            how it was chosen; None: none (robots.datasheets, [robot] datasheet).
    """

    def __init__(
        self,
        model: pin.Model,
        links: Sequence[LinkGeometry],
        ee_frame: str,
        continuous: Collection[str] = (),
    ) -> None:
        if not model.existFrame(ee_frame):
            names = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
            raise ConfigError("ee_frame", f"no frame {ee_frame!r}; the links are {names}")
        self.model = model
        self.data = model.createData()
        self.links = tuple(links)
        self.ee_frame = ee_frame
        self.ee_frame_id = model.getFrameId(ee_frame)
        self.continuous = np.array([name in continuous for name in self.joint_names], dtype=bool)
        self.acceleration_limit = rise_limit(model.velocityLimit, ACCEL_TIME)
        self.jerk_limit = rise_limit(self.acceleration_limit, JERK_TIME, "jerk_time")
        self.limit_sources = default_sources(self.nq)
        self.datasheet: str | None = None

    @classmethod
    def from_urdf(
        cls,
        path: str | Path,
        package_dirs: Sequence[str | Path] = (),
        ee_frame: str | None = None,
        max_links: int = MAX_LINKS,
        locked_joints: Mapping[str, float] | None = None,
        ee_offset: np.ndarray | None = None,
        decompose: bool | Collection[str] = False,
    ) -> RobotModel:
        """Load kinematics and collision shapes.

        Continuous joints keep one configuration entry each, with no position limit (their
        values wrap to (−π, π]); mimic joints follow the joint they mimic.

        Args:
            path: the URDF file.
            package_dirs: folders that hold the packages its package:// meshes name.
            ee_frame: the end-effector frame; default the last link.
            max_links: refuse a URDF with more links (checked before anything is built).
            locked_joints: joint name -> fixed value [rad or m]; these joints leave the model
                (a reduced model: nq drops by one each) and their links stay where the value
                puts them. Mimic joints of a locked joint are locked with it.
            ee_offset: pose (4×4) of the tool point in the `ee_frame` frame [m]; the tool
                point becomes a new frame, named `<ee_frame>_offset`, and the end effector.
            decompose: link meshes to split into convex parts with CoACD (cached on disk, see
                disk_cache.cache_folder) instead of one hull per separate part: True for
                every link, or link names; a non-convex link then keeps its concavities
                (tighter clearance) at the cost of a decomposition on first load.

        Returns:
            The robot model.
        """
        urdf = Path(path)
        if not urdf.is_file():
            raise ConfigError("urdf", f"{urdf}: file not found")
        _check_size(urdf, max_links)
        xml, unlimited, mimics, continuous = _prepare_urdf(urdf)
        failure: Exception | None = None
        with captured_output() as printed:  # the parser prints its errors past sys.stdout
            try:
                model = pin.buildModelFromXML(xml, mimic=True)
            except (RuntimeError, ValueError) as exc:
                failure = exc
        if failure is not None:
            said = f"; the parser said: {' '.join(printed[:2])}" if printed else ""
            raise ModelError(f"{urdf}: Pinocchio cannot build the model ({failure}){said}")
        _unbounded(model, unlimited)
        _check_serial(model, urdf)
        _check_magnitudes(model, urdf)
        if locked_joints:
            model = _lock(model, dict(locked_joints), mimics)
        shapes = collision_shapes(urdf, [Path(d) for d in package_dirs], decompose)
        links = []
        for name, items in shapes.items():
            if not model.existFrame(name, pin.FrameType.BODY):
                continue
            frame_id = model.getFrameId(name, pin.FrameType.BODY)
            links.append(
                LinkGeometry(name, frame_id, tuple(s for s, _ in items), tuple(T for _, T in items))
            )
        links.sort(key=lambda link: link.frame_id)
        if ee_frame is None:
            ee_frame = [f.name for f in model.frames if f.type == pin.FrameType.BODY][-1]
        if ee_offset is not None:
            ee_frame = _add_tool_frame(model, ee_frame, ee_offset)
        return cls(model, links, ee_frame, continuous)

    @classmethod
    def builtin(
        cls,
        name: str,
        ee_frame: str | None = None,
        locked_joints: Mapping[str, float] | None = None,
        ee_offset: np.ndarray | None = None,
        decompose: bool | Collection[str] = False,
    ) -> RobotModel:
        """A robot shipped with articula.

        Args:
            name: "iiwa14" (KUKA LBR iiwa 14 R820) or "ur5e" (Universal Robots UR5e).
            ee_frame: overrides its end-effector frame.
            locked_joints: joint name -> fixed value [rad or m] (see `from_urdf`).
            ee_offset: pose (4×4) of the tool point in the end-effector frame [m].
            decompose: link meshes to decompose with CoACD (see `from_urdf`).

        Returns:
            The robot model.
        """
        if name not in BUILTIN:
            raise ConfigError("builtin", f"unknown robot {name!r}; choose one of {sorted(BUILTIN)}")
        relative, default_frame = BUILTIN[name]
        with resources.as_file(resources.files("articula.robots") / "data" / relative) as urdf:
            return cls.from_urdf(
                urdf,
                ee_frame=ee_frame or default_frame,
                locked_joints=locked_joints,
                ee_offset=ee_offset,
                decompose=decompose,
            )

    @property
    def nq(self) -> int:
        """Number of joints."""
        return self.model.nq

    @property
    def joint_names(self) -> list[str]:
        """Names of the joints with a configuration entry, base to tip (no mimic joints)."""
        return [
            name
            for name, joint in zip(self.model.names[1:], self.model.joints[1:], strict=True)
            if joint.nq == 1
        ]

    @property
    def lower(self) -> np.ndarray:
        """Lower joint limits [rad or m]; −inf for a continuous joint."""
        return np.where(self.continuous, -np.inf, self.model.lowerPositionLimit)

    @property
    def upper(self) -> np.ndarray:
        """Upper joint limits [rad or m]; +inf for a continuous joint."""
        return np.where(self.continuous, np.inf, self.model.upperPositionLimit)

    @property
    def sample_range(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) ends of the range joint values are drawn from [rad or m]: the limits,
        or ±π for a continuous joint."""
        return (
            np.where(self.continuous, -np.pi, self.model.lowerPositionLimit),
            np.where(self.continuous, np.pi, self.model.upperPositionLimit),
        )

    @property
    def velocity_limit(self) -> np.ndarray:
        """Joint speed limits [rad/s or m/s]: the URDF's, or a datasheet's where tighter."""
        return self.model.velocityLimit.copy()

    def clip(self, q: np.ndarray) -> np.ndarray:
        """q clipped into the joint limits (the projection of Eq. 1.17); a continuous joint
        within ±2π, more than a period's motion from any q that `wrap` returns.

        Args:
            q: joint positions, shape (nq,) [rad or m].

        Returns:
            The clipped joint positions, shape (nq,) [rad or m].
        """
        return np.minimum(
            np.maximum(q, self.model.lowerPositionLimit), self.model.upperPositionLimit
        )

    def wrap(self, q: np.ndarray) -> np.ndarray:
        """q with each continuous joint's value wrapped to (−π, π] (the others as they are):
        the one function every joint value read from a file or an arm goes through.

        Args:
            q: joint positions, shape (..., nq) [rad or m].

        Returns:
            The wrapped joint positions, same shape [rad or m].
        """
        wrapped = np.pi - np.mod(np.pi - q, 2 * np.pi)
        # Just above π (π + 4e-16) the remainder rounds up to 2π: −π, which is π (kept) here.
        wrapped = np.where(wrapped <= -np.pi, np.pi, wrapped)
        return np.where(self.continuous, wrapped, q)

    def difference(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """a − b, the shortest way round for a continuous joint (in (−π, π]).

        Args:
            a: joint positions, shape (..., nq) [rad or m].
            b: joint positions, broadcastable to a [rad or m].

        Returns:
            The joint motion from b to a, same shape as a [rad or m].
        """
        return self.wrap(np.asarray(a) - np.asarray(b)) if self.continuous.any() else a - b

    def check_q(self, q: Sequence[float] | np.ndarray, field: str = "q") -> np.ndarray:
        """q as a float array of length nq, or ConfigError naming the problem.

        Args:
            q: joint positions, nq values [rad or m].
            field: the name the error reports the problem on.

        Returns:
            The joint positions, shape (nq,) [rad or m] (q itself if already such an array).
        """
        if type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (self.nq,):
            arr = q  # the planner's hot path: no copy
        else:
            arr = np.asarray(q, dtype=float)
            if arr.shape != (self.nq,):
                raise ConfigError(field, f"needs {self.nq} joint values (got shape {arr.shape})")
        # NaN fails the comparison too: only sane numbers reach Pinocchio.
        if not np.all(np.abs(arr) <= MAX_ANGLE):
            raise ConfigError(
                field, f"joint values must be finite and within ±{MAX_ANGLE:g} (got {arr.tolist()})"
            )
        return arr

    def forward(self, q: np.ndarray) -> None:
        """Update every frame placement for configuration q (unchecked, for hot loops).

        Args:
            q: joint positions, shape (nq,) [rad or m].
        """
        pin.framesForwardKinematics(self.model, self.data, q)

    def ee_pose(self, q: Sequence[float] | np.ndarray) -> np.ndarray:
        """Pose of the end-effector frame in the world (4×4).

        Args:
            q: joint positions, nq values [rad or m].

        Returns:
            The end-effector pose, shape (4, 4) [m].
        """
        self.forward(self.check_q(q))
        return self.data.oMf[self.ee_frame_id].homogeneous.copy()

    def ee_position(self, q: Sequence[float] | np.ndarray) -> np.ndarray:
        """Position [m] of the end-effector frame in the world.

        Args:
            q: joint positions, nq values [rad or m].

        Returns:
            The end-effector position, shape (3,) [m].
        """
        return self.ee_pose(q)[:3, 3].copy()

    def link_poses(self, q: Sequence[float] | np.ndarray) -> dict[str, np.ndarray]:
        """Pose (4×4, world) of every body frame, by link name.

        Args:
            q: joint positions, nq values [rad or m].

        Returns:
            Each link's pose in the world, shape (4, 4) [m], by link name.
        """
        self.forward(self.check_q(q))
        return {
            f.name: self.data.oMf[i].homogeneous.copy()
            for i, f in enumerate(self.model.frames)
            if f.type == pin.FrameType.BODY
        }

    def jacobian(self, q: Sequence[float] | np.ndarray) -> np.ndarray:
        """6×nq Jacobian of the end-effector: rows vx, vy, vz, wx, wy, wz in world axes.

        Args:
            q: joint positions, nq values [rad or m].

        Returns:
            The Jacobian, shape (6, nq): linear rows [m/rad], angular rows [rad/rad] (per m
            for a prismatic joint).
        """
        arr = self.check_q(q)
        return pin.computeFrameJacobian(
            self.model, self.data, arr, self.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        ).copy()

    def directional_gradients(
        self, q: np.ndarray, frame_ids: Sequence[int], points: np.ndarray, directions: np.ndarray
    ) -> np.ndarray:
        """Rows n_k·J_k (k × nq): how fast world point k [m], moving rigidly with frame
        frame_ids[k], moves along direction n_k per unit joint velocity; each joint's Jacobian
        is computed once.

        n·v_p = n·v_o + ω·((p − o) × n) at the parent joint's origin o, in world axes.

        Args:
            q: joint positions, shape (nq,) [rad or m] (unchecked).
            frame_ids: the frame each point moves with, k indices into the model's frames.
            points: the points in the world, shape (k, 3) [m].
            directions: the directions n_k in world axes, shape (k, 3) (unit vectors).

        Returns:
            The rows n_k·J_k, shape (k, nq) [m/rad] (dimensionless for a prismatic joint).
        """
        pin.computeJointJacobians(self.model, self.data, q)
        joints = [self.model.frames[f].parentJoint for f in frame_ids]
        unique = sorted(set(joints))
        frame = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        stack = np.array([pin.getJointJacobian(self.model, self.data, j, frame) for j in unique])
        origins = np.array([self.data.oMi[j].translation for j in unique])
        index = np.searchsorted(unique, joints)
        J = stack.reshape(-1, 6, self.nq)[index]
        lever = np.cross(points - origins.reshape(-1, 3)[index], directions)
        return np.einsum("ki,kin->kn", directions, J[:, :3]) + np.einsum(
            "ki,kin->kn", lever, J[:, 3:]
        )
