"""The arm's controller for a live loop: one control period per call, obstacles moved per call.

`track` (and so `articula plan`) drives the same object along a reference path, so a live loop
and a planned run share one code path:

    controller = OnlineController.from_spec(scene, PlannerSpec(method="qp"), live_obstacles=True)
    q = controller.reset(q_measured)        # checks the start, compiles every kernel
    every 10 ms:
        q = controller.step(target, {"box": pose_from_camera}, q_measured=read_joints())
        send q to the arm
    (target: a position [m], a 4×4 pose for a pose task, or a Target; without q_measured the
    tool's lag behind the commands is not corrected)
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence

import numpy as np

from articula.errors import ConfigError, GeometryError, InfeasibleError
from articula.planning.config import PlannerSpec, make_planner
from articula.planning.planner import Planner
from articula.planning.task import Target, unit
from articula.scene.obstacles import Obstacle, check_pose
from articula.scene.scene import Scene

MAX_LEAD = 0.05  # [m] the largest correction of a target for the tool's lag (anti-windup)
LEAD_TIME = 1.0  # [s] time constant of that correction: the measured error integrated over it
MAX_LAG = 16  # [periods] the oldest period a measurement may answer (step's lag)


class LivePose:
    """An obstacle pose a live loop sets each period; as a pose function it ignores time.

    Args:
        pose: the obstacle's starting pose, 4×4 homogeneous transform in the world [m].

    Attributes:
        pose: the last pose set, 4×4 homogeneous transform in the world [m].
    """

    def __init__(self, pose: np.ndarray) -> None:
        self.pose = np.array(pose, dtype=float)

    def __call__(self, t: float) -> np.ndarray:
        """The last pose set [4×4, world].

        Args:
            t: time [s], ignored.

        Returns:
            The obstacle's pose, 4×4 homogeneous transform in the world [m].
        """
        return self.pose


def with_live_obstacles(scene: Scene) -> tuple[Scene, dict[str, LivePose]]:
    """The scene with every obstacle at a pose a live loop sets (starting where it is at t = 0).

    Args:
        scene: the robot and its obstacles.

    Returns:
        The scene with live obstacles, and obstacle name -> its LivePose.
    """
    live = {o.name: LivePose(o.pose_at(0.0)) for o in scene.obstacles}
    obstacles = [Obstacle(o.name, o.parts, live[o.name]) for o in scene.obstacles]
    robot, pairs = scene.robot, scene.self_pair_names
    moved = Scene(robot, obstacles, scene.broadphase, scene.metric, pairs, scene.self_d_min)
    return moved, live


class OnlineController:
    """A planner one control period at a time, from a start it checks.

    Args:
        planner: any articula planner (BAORNN, baornn-improved, pinv, dls, qp).
        dt: the control period [s].
        live: obstacle name -> its LivePose, for the obstacles step() may move.

    Attributes:
        periods: control periods since reset; the time is periods · dt [s].
        q: the last commanded joint positions, shape (n,) [rad]; None before reset.
        q_measured: the last measured joint positions (the start after reset), shape (n,)
            [rad]; None before reset.
        lead: how far [m] the targets are moved to make up for the measured tool's lag behind
            the planner's tool (integrated over LEAD_TIME), shape (3,).
        held: the start's tool pose, whose orientation and axis fill in what a target lacks.
        target: the last period's target, completed.
    """

    def __init__(
        self, planner: Planner, dt: float, live: Mapping[str, LivePose] | None = None
    ) -> None:
        if not (np.isfinite(dt) and dt > 0):
            raise ConfigError("dt", f"must be finite and > 0 s (got {dt})")
        self.planner = planner
        self.dt = dt
        self.live = dict(live or {})
        self.periods = 0  # since reset; the time is periods · dt [s]
        self.q: np.ndarray | None = None
        self.q_measured: np.ndarray | None = None
        self.lead = np.zeros(3)
        self.held: Target | None = None  # the start's orientation and tool axis
        self.target: Target | None = None  # the last period's, complete
        # The planner's tool for each of the last periods' targets (its command's less the lead
        # it was planned with) [m], newest last.
        self._intended: deque[np.ndarray] = deque(maxlen=MAX_LAG + 1)

    @classmethod
    def from_spec(
        cls, scene: Scene, spec: PlannerSpec, seed: int = 0, live_obstacles: bool = False
    ) -> OnlineController:
        """The controller of a [planner] table on `scene`; with `live_obstacles`, step() takes
        each obstacle's pose (the scene's poses are the starting ones).

        Args:
            scene: the robot and its obstacles.
            spec: the [planner] table: method, its parameters and the control period dt.
            seed: seed of the planner's random numbers (BAORNN's).
            live_obstacles: let step() move every obstacle of the scene.

        Returns:
            A controller to reset() before its first step().
        """
        live: dict[str, LivePose] = {}
        if live_obstacles:
            scene, live = with_live_obstacles(scene)
        return cls(make_planner(spec, scene, seed), spec.dt, live)

    def reset(
        self,
        q: Sequence[float] | np.ndarray,
        velocity: Sequence[float] | np.ndarray | None = None,
    ) -> np.ndarray:
        """Start from q [rad] at t = 0, once the start is checked; every compiled kernel is
        compiled (or loaded from numba's cache) before this returns, so the first step is as
        fast as the others.

        Args:
            q: the arm's measured joint positions, shape (n,) [rad].
            velocity: the arm's joint velocities [rad/s], shape (n,), for the acceleration
                limit of the first step; None: at rest.

        Returns:
            A copy of the checked start, shape (n,) [rad] (continuous joints wrapped).

        Raises:
            InfeasibleError: naming `q0`, for a start outside the joint limits, in collision
                (with an obstacle or, for a checked link pair, with itself), within d_min of an
                obstacle or within self_d_min between two links.
        """
        scene, robot = self.planner.scene, self.planner.scene.robot
        start = robot.wrap(robot.check_q(q, "q0"))
        outside = np.flatnonzero((start < robot.lower) | (start > robot.upper))
        if outside.size:
            j = int(outside[0])  # the first, named with its range and where the range came from
            raise InfeasibleError(
                f"the start breaks the joint limits (Eq. 1.9): {robot.joint_names[j]} = "
                f"{start[j]:.4f} outside [{robot.lower[j]:.4f}, {robot.upper[j]:.4f}] "
                f"({robot.limit_sources['position'][j]}); move the start within them",
                "q0",
            )
        if scene.self_pairs:
            d_self = scene.self_distances(start)
            k = int(np.argmin(d_self))
            if d_self[k] <= scene.self_d_min:
                a, b = scene.self_pair_names[k]
                what = "collides with itself" if d_self[k] <= 0 else "is too close to itself"
                raise InfeasibleError(
                    f"the start {what}: links {a} and {b} are {d_self[k]:.4f} m apart, within "
                    f"self_d_min = {scene.self_d_min} m; move the start, lower "
                    "robot.self_d_min or allow the pair in robot.allow_pairs",
                    "q0",
                )
        if scene.obstacles:
            d0 = scene.clearances(start)[0]
            if d0 <= 0:
                raise InfeasibleError(f"the start collides with an obstacle (d = {d0:.4f} m)", "q0")
            if d0 <= self.planner.d_min:
                raise InfeasibleError(
                    f"the start is {d0:.4f} m from an obstacle, within d_min = "
                    f"{self.planner.d_min} m (Eq. 1.12); lower d_min or move the start",
                    "q0",
                )
        pose = robot.ee_pose(start)
        rotation = np.ascontiguousarray(pose[:3, :3])  # the kernels compile for C-ordered arrays
        self.held = Target(pose[:3, 3].copy(), rotation, rotation @ self.planner.task.tool_axis)
        self.planner.warm_up(start, self.held)
        self.planner.reset()
        if velocity is not None:
            moving = robot.check_q(velocity, "velocity")
            self.planner.follow(moving * self.dt)
        self.q, self.q_measured, self.periods = start, start.copy(), 0
        self.lead, self.target = np.zeros(3), None  # nothing measured against yet
        self._intended.clear()
        return start.copy()

    def step(
        self,
        target: Sequence[float] | np.ndarray | Target,
        obstacle_poses: Mapping[str, np.ndarray] | None = None,
        q_measured: Sequence[float] | np.ndarray | None = None,
        lag: int = 0,
    ) -> np.ndarray:
        """One control period toward the target; obstacle_poses moves live obstacles first.

        The commands form one continuous stream within the speed and acceleration limits
        (what an arm's controller checks), each planned from the one before. With q_measured
        the loop closes on the arm: the targets move ahead by the measured tool's lag behind
        the planner's own tool for the target (the command's, less the lead) integrated over
        LEAD_TIME (at most MAX_LEAD), so the measured tool converges to what the planner
        chose while a servo that lags gets commands ahead of it (a plan from the measured
        joints would hold a lagging servo back: docs/deviations.md).

        Args:
            target: a position (3,) [m], a pose (4×4, world) or a Target; an orientation or
                axis the task needs and the target lacks is the start's, held.
            obstacle_poses: live obstacle name -> its new pose (4×4, world) [m]; None: none
                moves.
            q_measured: the arm's joint positions measured at the start of the period, shape
                (n,) [rad]; None: the lag found last (none before any measurement) stays.
            lag: how many periods before the last one q_measured was taken (a pipelined loop
                plans ahead of the arm: its measurement answers an older period's target);
                0 to MAX_LAG.

        Returns:
            The new joint positions to send to the arm, shape (n,) [rad] (continuous joints
            wrapped to (−π, π]).
        """
        if self.q is None or self.held is None or self.q_measured is None:
            raise ConfigError("reset", "call reset(q) with the arm's configuration first")
        robot = self.planner.scene.robot
        measured = None
        if q_measured is not None:
            measured = robot.wrap(robot.check_q(q_measured, "q_measured"))
        for name, pose in (obstacle_poses or {}).items():
            if name not in self.live:
                known = ", ".join(sorted(self.live)) or "none (build it with live_obstacles)"
                raise ConfigError("obstacle_poses", f"no live obstacle {name!r}; live: {known}")
            try:
                pose = np.asarray(pose, dtype=float)
                self.live[name].pose = check_pose(f"obstacle {name!r}", pose)
            except GeometryError as exc:
                raise ConfigError(f"obstacle_poses.{name}", str(exc)) from None
        if measured is not None:
            self.q_measured = measured
            if not 0 <= lag <= MAX_LAG:
                raise ConfigError("lag", f"must be within [0, {MAX_LAG}] periods (got {lag})")
            if len(self._intended) > lag:  # the command the measured arm aims at
                # Its lag behind the tool the planner chose for that target (the command's
                # less the lead it was given), not behind the target: a deviation the planner
                # chose (clearance before the path, Eq. 1.11) integrated here winds the lead
                # up against it, and the loop drifted off the path (docs/deviations.md).
                error = self._intended[-1 - lag] - robot.ee_position(measured)
                lead = self.lead + self.dt / LEAD_TIME * error
                self.lead = lead * min(1.0, MAX_LEAD / max(float(np.linalg.norm(lead)), 1e-12))
        self.target = self._complete(target)
        led, given = self.target, self.lead.copy()
        if self.lead.any():
            led = Target(self.target.position + self.lead, self.target.rotation, self.target.axis)
        self.q = robot.wrap(self.planner.step(self.q, led, self.t))
        self._intended.append(robot.ee_position(self.q) - given)
        self.periods += 1
        return self.q.copy()

    def _complete(self, target: Sequence[float] | np.ndarray | Target) -> Target:
        """The target as a checked Target, with the held orientation and axis filled in."""
        if not isinstance(target, Target):
            arr = np.asarray(target, dtype=float)
            if arr.shape == (4, 4):
                try:
                    check_pose("the target", arr)
                except GeometryError as exc:
                    raise ConfigError("target", str(exc)) from None
                target = Target(arr[:3, 3].copy(), arr[:3, :3].copy())
            else:
                target = Target(arr)
        # C-ordered copies: the compiled kernels are compiled for those (a strided view, such as
        # a column of a pose, would compile them again in the middle of a run).
        position = np.ascontiguousarray(target.position, dtype=float)
        if position.shape != (3,) or not np.isfinite(position).all():
            raise ConfigError(
                "target", f"needs 3 finite coordinates [m] or a 4×4 pose (got {position.tolist()})"
            )
        held = self.held
        rotation = (
            held.rotation
            if target.rotation is None
            else np.ascontiguousarray(target.rotation, dtype=float)
        )
        axis = held.axis if target.axis is None else unit(target.axis, "target.axis")
        return Target(position, rotation, axis)

    @property
    def t(self) -> float:
        """The time of the next period [s] since reset."""
        return self.periods * self.dt
