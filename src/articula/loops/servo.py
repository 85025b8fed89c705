"""The servo stream: a plan's joint set-points, one per control period, turned into what an
arm's joint servo takes at its own rate (a Franka 1 kHz, a UR's servoJ 500 Hz), within the
arm's position, velocity, acceleration and jerk limits.

The stream is the uniform cubic B-spline whose control points are the set-points. Its
velocity on a period is a convex combination of the control points' first differences / dt,
its acceleration one of their second differences / dt², its jerk their third difference / dt³,
and its position one of the control points: so the stream keeps every limit that the
control points keep as differences, by construction, at any servo rate. A control point is the
set-point itself whenever that keeps the limits relative to the control points before it (the
planners' limits = "velocity+acceleration+jerk" make it so, but for a strained period); else
the nearest point that does (RateLimits.box, which also brakes for the position limits).

The spline through control points c_k passes (c_{k-1} + 4 c_k + c_{k+1}) / 6 at knot k: within
a sixth of one period's change of motion of the set-point, two periods after the set-point was
commanded (the segment of a period needs the newest set-point as its last control point).
docs/architecture.md says why this and not Ruckig's online generator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError, ModelError
from articula.loops.tracking import PlanResult
from articula.planning.rate_limits import RateLimits, braking_path
from articula.robots.model import RobotModel

__all__ = [
    "LAG_PERIODS",
    "ServoLimits",
    "ServoStream",
    "ServoTrace",
    "run_stream",
    "servo_trace",
    "ticks_per_period",
]

LAG_PERIODS = 2  # a set-point commanded at t is passed at t + LAG_PERIODS · dt
ROUND_OFF = 1e-9  # [rad] a set-point this close to the limits' box keeps them


@dataclass(frozen=True)
class ServoLimits:
    """The joint limits a servo stream keeps.

    Attributes:
        lower: lower joint limits, shape (n,) [rad or m] (−inf: none).
        upper: upper joint limits, shape (n,) [rad or m] (+inf: none).
        velocity: largest joint speeds, shape (n,) [rad/s or m/s].
        acceleration: largest joint accelerations, shape (n,) [rad/s² or m/s²].
        jerk: largest joint jerks, shape (n,) [rad/s³ or m/s³].
    """

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray

    def __post_init__(self) -> None:
        for name in ("velocity", "acceleration", "jerk"):
            value = np.asarray(getattr(self, name), dtype=float)
            if not np.all(np.isfinite(value) & (value > 0)):
                key = "robot.urdf" if name == "velocity" else f"robot.{name}_limits"
                raise ConfigError(
                    key,
                    f"a servo stream needs a finite {name} limit > 0 for every joint "
                    f"(got {value.tolist()})",
                )
            object.__setattr__(self, name, value)

    @classmethod
    def of(cls, robot: RobotModel) -> ServoLimits:
        """The robot's own limits (the URDF's positions and speeds, [robot]'s acceleration
        and jerk).

        Args:
            robot: the robot.

        Returns:
            Its limits.
        """
        free = robot.continuous  # a continuous joint turns without end: no position limit
        return cls(
            np.where(free, -np.inf, robot.model.lowerPositionLimit),
            np.where(free, np.inf, robot.model.upperPositionLimit),
            robot.velocity_limit,
            robot.acceleration_limit,
            robot.jerk_limit,
        )

    def as_record(self) -> dict[str, list[float]]:
        """The limits for a run's record: velocity, acceleration, jerk, per joint (SI).

        Returns:
            Name -> one value per joint.
        """
        return {k: getattr(self, k).tolist() for k in ("velocity", "acceleration", "jerk")}


class ServoStream:
    """The online stream: `reset` at the start, then one `period` per set-point.

    Args:
        limits: the joint limits to keep.
        dt: the control period of the set-points [s].
        rate: the servo rate [Hz]; rate · dt must be a whole number of ticks.

    Attributes:
        ticks: servo samples per control period.
        box: the limits' box each new control point is kept in (as the planners' is).
        clipped: set-points so far that broke a limit and were replaced by the nearest
            control point that keeps them.
    """

    def __init__(self, limits: ServoLimits, dt: float, rate: float) -> None:
        self.limits, self.dt, self.ticks = limits, dt, ticks_per_period(rate, dt)
        self.clipped = 0
        self.box = RateLimits(limits.velocity, dt, limits.acceleration, limits.jerk)
        self._points: np.ndarray | None = None  # the last three control points
        u = np.arange(1, self.ticks + 1) / self.ticks
        self._basis = _basis(u, dt)

    def reset(self, q: np.ndarray) -> None:
        """Start at rest at q.

        Args:
            q: joint positions, shape (n,) [rad].
        """
        q = np.asarray(q, dtype=float)
        self._points = np.stack([q, q, q])
        self.box.reset()
        self.clipped = 0

    def period(self, setpoint: np.ndarray) -> np.ndarray:
        """The samples of one control period after a new set-point.

        Args:
            setpoint: the set-point commanded at the period's start, shape (n,) [rad].

        Returns:
            Position, velocity and acceleration at each tick of the period, shape
            (ticks, 3, n) [rad, rad/s, rad/s²]; the last tick is at the period's end.
        """
        if self._points is None:
            raise ModelError("ServoStream.period before reset: call reset(q0) first")
        last = self._points[-1]
        lower, upper = self.box.box(last, self.limits.lower, self.limits.upper)
        point = np.clip(setpoint, lower, upper)
        # A set-point outside by no more than the boxes' round-off is kept as it is: the two
        # boxes (the planner's and this one) round alike only while they start alike.
        point = np.where(np.abs(point - setpoint) > ROUND_OFF, point, setpoint)
        if not np.array_equal(point, setpoint):
            self.clipped += 1
        self.box.record(point - last)
        control = np.vstack([self._points, point])  # (4, n): this period's control points
        self._points = control[1:]
        return np.einsum("tdk,kn->tdn", self._basis, control)

    def stopping_points(self) -> np.ndarray:
        """The set-points that bring the arm to rest from where the stream is: every joint
        braking as hard as its limits let it (rate_limits.braking_path, the braking the
        planners keep room for), then three periods held where it stopped.

        Returns:
            The set-points, one per period, shape (periods, n) [rad].
        """
        if self._points is None:
            raise ModelError("ServoStream.stopping_points before reset: call reset(q0) first")
        before, last, now = self._points
        box = self.box
        jerk = np.zeros(0) if box.jerk_change is None else box.jerk_change
        stops = now + braking_path(now - last, last - before, box.change, jerk)
        end = stops[-1] if len(stops) else now
        return np.vstack([stops.reshape(-1, now.size), np.tile(end, (3, 1))])


def ticks_per_period(rate: float, dt: float) -> int:
    """How many servo ticks one control period holds.

    Args:
        rate: the servo rate [Hz].
        dt: the control period [s].

    Returns:
        rate · dt, when it is a whole number ≥ 1 (else ConfigError naming servo.rate).
    """
    ticks = round(rate * dt)
    if ticks < 1 or abs(ticks - rate * dt) > 1e-6:
        raise ConfigError(
            "servo.rate",
            f"{rate:g} Hz is not a whole number of ticks per {dt:g} s period (planner.dt); "
            f"use a multiple of {1 / dt:g} Hz",
        )
    return ticks


def _basis(u: np.ndarray, dt: float) -> np.ndarray:
    """The uniform cubic B-spline's weights of its 4 control points for position, velocity
    and acceleration at each u in (0, 1] of a period dt, shape (len(u), 3, 4)."""
    w = np.empty((u.size, 3, 4))
    w[:, 0] = (
        np.column_stack(
            [(1 - u) ** 3, 3 * u**3 - 6 * u**2 + 4, -3 * u**3 + 3 * u**2 + 3 * u + 1, u**3]
        )
        / 6
    )
    w[:, 1] = np.column_stack(
        [-3 * (1 - u) ** 2, 9 * u**2 - 12 * u, -9 * u**2 + 6 * u + 3, 3 * u**2]
    ) / (6 * dt)
    w[:, 2] = np.column_stack([1 - u, 3 * u - 2, 1 - 3 * u, u]) / dt**2
    return w


@dataclass(frozen=True)
class ServoTrace:
    """A plan's servo stream.

    Attributes:
        t: time of each sample since the start [s], shape (m,); the first is the start at rest.
        q: joint positions, shape (m, n) [rad].
        qd: joint velocities, shape (m, n) [rad/s].
        qdd: joint accelerations, shape (m, n) [rad/s²].
        deviation: largest joint deviation from each set-point when the stream passes it
            (LAG_PERIODS after it was commanded), shape (k,) [rad].
        clipped: set-points that broke a limit (ServoStream.clipped).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    deviation: np.ndarray
    clipped: int

    def columns(self) -> dict[str, np.ndarray]:
        """servo.parquet's columns: t, q_1..q_n, qd_1..qd_n, qdd_1..qdd_n.

        Returns:
            Column name -> values, shape (m,).
        """
        columns = {"t": self.t}
        for name, values in (("q", self.q), ("qd", self.qd), ("qdd", self.qdd)):
            columns.update({f"{name}_{j + 1}": values[:, j] for j in range(values.shape[1])})
        return columns

    def ratios(self, limits: ServoLimits) -> dict[str, float]:
        """The stream's largest speed, acceleration and jerk over the limits, by first, second
        and third differences of the positions (what the servo receives).

        Args:
            limits: the limits the stream keeps.

        Returns:
            max_velocity_ratio, max_acceleration_ratio, max_jerk_ratio.
        """
        h = self.t[1] - self.t[0]
        ratios = {}
        for order, name in enumerate(("velocity", "acceleration", "jerk"), start=1):
            rate = np.abs(np.diff(self.q, order, axis=0)) / h**order
            ratios[f"max_{name}_ratio"] = float(np.max(rate / getattr(limits, name), initial=0.0))
        return ratios


def servo_trace(
    setpoints: np.ndarray, q0: np.ndarray, dt: float, stream: ServoStream
) -> ServoTrace:
    """Stream a plan's set-points from rest at q0, then bring the arm to rest: past the last
    set-point every joint brakes as hard as its limits let it (rate_limits.braking_path, the
    braking the planners keep room for) and the stream holds where it stopped, so that it
    ends at rest within every limit.

    Args:
        setpoints: the set-point commanded at each control period, shape (k, n) [rad].
        q0: where the arm starts, at rest, shape (n,) [rad].
        dt: the control period [s].
        stream: the servo stream (reset here).

    Returns:
        The stream: ticks samples per set-point and per braking or holding period after the
        start.
    """
    q0 = np.asarray(q0, dtype=float)
    stream.reset(q0)
    periods = [stream.period(setpoint) for setpoint in setpoints]
    clipped = stream.clipped
    periods += [stream.period(point) for point in stream.stopping_points()]
    periods = np.stack(periods)  # (periods, ticks, 3, n)
    passed = periods[LAG_PERIODS - 1 : LAG_PERIODS - 1 + len(setpoints), -1, 0]
    deviation = np.max(np.abs(passed - setpoints), axis=1)
    start = np.stack([q0, np.zeros_like(q0), np.zeros_like(q0)])[None]
    s = np.concatenate([start, periods.reshape(-1, 3, q0.size)])
    t = np.arange(len(s)) * (dt / stream.ticks)
    return ServoTrace(t, s[:, 0], s[:, 1], s[:, 2], deviation, clipped)


def run_stream(run: PlanResult, robot: RobotModel, rate: float) -> tuple[ServoTrace, dict]:
    """A tracking run's servo stream at `rate` [Hz] within the robot's limits, and its
    metrics.

    A continuous joint's set-points are unwrapped first (its shortest way round from one to
    the next), so that the stream never swings round the long way.

    Args:
        run: the tracking run, with its start q0.
        robot: the robot, for its limits and continuous joints.
        rate: the servo rate [Hz], a whole number of ticks per period.

    Returns:
        The stream, and its metrics: servo_rate_hz, servo_max_velocity_ratio,
        servo_max_acceleration_ratio, servo_max_jerk_ratio (by differences of its positions),
        servo_max_deviation [rad] (from a set-point when the stream passes it), servo_lag_s
        (how long after a set-point was commanded) and servo_clipped (set-points that broke
        a limit).
    """
    if run.q0 is None or len(run.t) < 2:
        raise ModelError("run_stream needs a run with its start q0 and two periods or more")
    dt = float(run.t[1] - run.t[0])
    q = np.vstack([run.q0, run.q])
    unwrapped = run.q0 + np.cumsum(robot.difference(q[1:], q[:-1]), axis=0)
    setpoints = np.where(robot.continuous, unwrapped, run.q)  # the others exactly as sent
    limits = ServoLimits.of(robot)
    trace = servo_trace(setpoints, run.q0, dt, ServoStream(limits, dt, rate))
    ratios = trace.ratios(limits)
    metrics = {
        "servo_rate_hz": float(rate),
        **{f"servo_{k}": v for k, v in ratios.items()},
        "servo_max_deviation": float(np.max(trace.deviation)),
        "servo_lag_s": LAG_PERIODS * dt,
        "servo_clipped": float(trace.clipped),
    }
    return trace, metrics
