"""Joint speed, acceleration and jerk limits as a box the next configuration must stay in."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from articula.errors import ConfigError
from articula.numba_cache import jit

# The box is narrowed by this relative amount, so that round-off in q_{k+1} = q_k + motion
# cannot put a finite difference of the commanded positions a hair above a limit.
ROUND_OFF = 1e-9


@dataclass
class RateLimits:
    """Per-period bounds on joint motion, relative to the motion of the period before.

    With acceleration limits a joint also brakes in time for its position limits: its motion
    m toward a limit keeps m + m²/(2 a dt²) within the room left, the distance it needs to
    stop at its largest deceleration, so the next box is never empty. A jerk limit bounds how
    much the change of motion itself changes from one period to the next (j dt³); where that
    would leave the box empty (a brake the jerk limit cannot ramp into in time), the position,
    speed and acceleration limits win and the period is strained.

    Attributes:
        velocity: the largest joint speeds [rad/s or m/s], one per joint (inf: none).
        dt: the control period [s].
        acceleration: the largest joint accelerations [rad/s² or m/s²], one per joint (inf:
            none); None: no acceleration limit.
        jerk: the largest joint jerks [rad/s³ or m/s³], one per joint (inf: none); None: no
            jerk limit (kept only with an acceleration limit).
        strained: whether the last box could not keep every limit (the motion before broke
            one: a measured motion, or limits changed during the run); it then keeps the
            position and speed limits and comes as close to the acceleration limit as it can.
    """

    velocity: np.ndarray
    dt: float
    acceleration: np.ndarray | None = None
    jerk: np.ndarray | None = None
    strained: bool = field(default=False, init=False)
    _last_motion: np.ndarray | None = field(default=None, init=False, repr=False)
    _motion_before: np.ndarray | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self.velocity = np.asarray(self.velocity, dtype=float)
        if not (np.all(self.velocity > 0) and np.isfinite(self.dt) and self.dt > 0):
            raise ConfigError("RateLimits.velocity", "speeds and dt must be > 0")
        for name in ("acceleration", "jerk"):
            value = getattr(self, name)
            if value is None:
                continue
            value = np.broadcast_to(np.asarray(value, dtype=float), self.velocity.shape).copy()
            if not np.all(value > 0):
                raise ConfigError(f"RateLimits.{name}", f"must be > 0 (got {value.tolist()})")
            setattr(self, name, value)
        if self.jerk is not None and self.acceleration is None:
            raise ConfigError("RateLimits.jerk", "needs an acceleration limit too")

    def box(
        self, q: np.ndarray, lower: np.ndarray, upper: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The joint limits [lower, upper] narrowed to what one period can reach from q.

        Args:
            q: joint positions at the start of the period, shape (nq,) [rad or m].
            lower: lower joint limits, shape (nq,) [rad or m] (−inf: none).
            upper: upper joint limits, shape (nq,) [rad or m] (+inf: none).

        Returns:
            The narrowed (lower, upper) bounds, each shape (nq,) [rad or m].
        """
        reach = (1.0 - ROUND_OFF) * self.velocity * self.dt
        unlimited = np.full_like(q, np.inf)
        change = unlimited if self.change is None else self.change
        jerk = unlimited if self.jerk is None else self.jerk_change
        last = np.zeros_like(q) if self._last_motion is None else self._last_motion
        before = np.zeros_like(q) if self._motion_before is None else self._motion_before
        low, high, self.strained = _box(q, lower, upper, reach, change, jerk, last, last - before)
        return low, high

    def record(self, motion: np.ndarray) -> None:
        """Remember the motion of the period that ended (for the acceleration limit).

        Args:
            motion: joint displacement over that period, shape (nq,) [rad or m].
        """
        self._motion_before = self._last_motion
        self._last_motion = np.array(motion, dtype=float)

    @property
    def change(self) -> np.ndarray | None:
        """Each joint's largest change of motion per period, a·dt² [rad or m]; None without
        an acceleration limit."""
        if self.acceleration is None:
            return None
        return (1.0 - ROUND_OFF) * self.acceleration * self.dt**2

    @property
    def jerk_change(self) -> np.ndarray | None:
        """Each joint's largest change of its change of motion per period, j·dt³ [rad or m];
        None without a jerk limit."""
        if self.jerk is None:
            return None
        return (1.0 - ROUND_OFF) * self.jerk * self.dt**3

    @property
    def last_motion(self) -> np.ndarray | None:
        """The joint motion of the period that ended [rad or m]; None: at rest."""
        return self._last_motion

    def reset(self) -> None:
        """Forget the last motion: the arm starts at rest."""
        self._last_motion = self._motion_before = None
        self.strained = False


@jit()
def _box(q, lower, upper, reach, change, jerk, last, last_change):
    """RateLimits.box in one compiled call: (lower, upper, strained); change (jerk) is inf for
    a joint without an acceleration (jerk) limit."""
    n = q.size
    low, high = np.empty(n), np.empty(n)
    strained = False
    for j in range(n):
        lo = max(-reach[j], lower[j] - q[j])
        hi = min(reach[j], upper[j] - q[j])
        c = change[j]
        if math.isfinite(c):
            if math.isfinite(jerk[j]):  # braking must first ramp its deceleration up
                below = _ramped_reach(q[j] - lower[j], -last[j], -last_change[j], c, jerk[j])
                lo = max(lo, -below)
                hi = min(hi, _ramped_reach(upper[j] - q[j], last[j], last_change[j], c, jerk[j]))
            else:
                lo = max(lo, -_braking_reach(q[j] - lower[j], c))
                hi = min(hi, _braking_reach(upper[j] - q[j], c))
            fast_lo, fast_hi = max(lo, last[j] - c), min(hi, last[j] + c)
            if fast_lo > fast_hi:  # the acceleration box misses the rest: its nearest point
                strained = True
                fast_lo = fast_hi = min(max(last[j], lo), hi)
            lo, hi = fast_lo, fast_hi
            if math.isfinite(jerk[j]):
                steady = last[j] + last_change[j]  # the motion with the change kept
                # A speeding-up joint must ramp its acceleration down before the speed limit.
                hi = min(hi, _ramped_speed(reach[j], last[j], jerk[j]))
                lo = max(lo, -_ramped_speed(reach[j], -last[j], jerk[j]))
                smooth_lo, smooth_hi = max(lo, steady - jerk[j]), min(hi, steady + jerk[j])
                if smooth_lo > smooth_hi + ROUND_OFF * jerk[j]:  # the jerk box misses the rest
                    strained = True
                    smooth_lo = smooth_hi = min(max(steady, lo), hi)  # its nearest point
                lo, hi = smooth_lo, min(max(smooth_hi, smooth_lo), hi)
        low[j] = q[j] + lo
        high[j] = q[j] + max(hi, lo)
    return low, high, strained


@jit()
def _braking_reach(room: float, change: float) -> float:
    """The largest motion m [rad] toward a limit `room` away that can still stop before it,
    m + m²/(2c) ≤ room with c the largest change of motion per period; room itself (≤ 0: back
    inside) where the limit is reached or unbounded."""
    if room <= 0.0 or not math.isfinite(room):
        return room
    return change * (math.sqrt(1.0 + 2.0 * room / change) - 1.0)


@jit()
def braking_after(motion, last, change, jerk):
    """How far [rad] each joint moves on after a period's `motion` (the period before moved
    `last`) when it brakes as hard as its limits let it: at once by its largest change of
    motion per period `change` (m·|m|/(2c); 0 where c is inf), or, with a jerk limit (`jerk`:
    the largest change of that change per period; empty or inf: none), with the braking
    ramped up first.

    Args:
        motion: the joint motion over the period, shape (nq,) [rad].
        last: the joint motion over the period before, shape (nq,) [rad].
        change: the largest change of motion per period, a·dt², shape (nq,) [rad].
        jerk: the largest change of the change of motion per period, j·dt³, shape (nq,) or
            (0,) [rad].

    Returns:
        The signed travel until each joint stops, shape (nq,) [rad].
    """
    travel = np.zeros(motion.size)
    for j in range(motion.size):
        c, m = change[j], motion[j]
        if not math.isfinite(c):
            continue
        if jerk.size == 0 or not math.isfinite(jerk[j]):
            travel[j] = m * abs(m) / (2.0 * c)
        else:
            sign = 1.0 if m >= 0.0 else -1.0
            toward = _stopping_travel(sign * m, sign * last[j], c, jerk[j])
            travel[j] = sign * (toward - sign * m)
    return travel


@jit()
def braking_path(motion, last, change, jerk):
    """Where each later period ends, as offsets [rad] from this period's end, while every
    joint brakes as hard as its limits let it (braking_after), until all have stopped.

    Args:
        motion: the joint motion over the period, shape (nq,) [rad].
        last: the joint motion over the period before, shape (nq,) [rad].
        change: the largest change of motion per period, a·dt², shape (nq,) [rad] (inf: none,
            the joint stops at once).
        jerk: the largest change of the change of motion per period, j·dt³, shape (nq,) or
            (0,) [rad] (empty or inf: none).

    Returns:
        The offsets of each braking period's end, shape (periods, nq) [rad]; the last is
        where the arm stops.
    """
    n = motion.size
    sign = np.where(motion >= 0.0, 1.0, -1.0)
    moving = np.abs(motion)
    step = sign * (motion - last)
    offset = np.zeros(n)
    rows = []
    while np.any(moving > 0.0):
        for j in range(n):
            if moving[j] <= 0.0:
                continue
            if not math.isfinite(change[j]):
                moving[j] = 0.0
                continue
            ramp = jerk[j] if jerk.size and math.isfinite(jerk[j]) else np.inf
            step[j] = max(step[j] - ramp, -change[j])
            moving[j] = max(moving[j] + step[j], 0.0)
            offset[j] += sign[j] * moving[j]
        rows.append(offset.copy())
    out = np.zeros((len(rows), n))
    for k in range(len(rows)):
        out[k] = rows[k]
    return out


@jit()
def _ramped_reach(
    room: float, last: float, last_change: float, change: float, jerk: float
) -> float:
    """The largest motion m [rad] toward a limit `room` away, after a motion `last` toward it
    that changed by `last_change`, that can still stop before it when the change of motion is
    at most `change` and moves by at most `jerk` per period: _braking_reach with the
    deceleration ramped up (bisection on m, whose stopping travel grows with it); room itself
    where the limit is reached or unbounded, and the hardest braking the limits allow where
    even that cannot stop in time."""
    if room <= 0.0 or not math.isfinite(room):
        return room
    low = max(last - change, last + last_change - jerk)  # the hardest braking it can start
    high = min(last + change, room)
    room *= 1.0 - ROUND_OFF  # slack for the round-off of the positions that follow
    if _stopping_travel(low, last, change, jerk) > room:
        return low
    if _stopping_travel(high, last, change, jerk) <= room:
        return high
    for _ in range(60):
        mid = 0.5 * (low + high)
        if _stopping_travel(mid, last, change, jerk) <= room:
            low = mid
        else:
            high = mid
    return low


@jit()
def _stopping_travel(m: float, last: float, change: float, jerk: float) -> float:
    """How far a joint travels toward a limit from a period's motion m after `last`, braking
    as hard as the limits let it (the change of motion falls by jerk a period, down to
    −change) until it stops."""
    travel = motion = m
    step = m - last
    while motion > 0.0:
        step = max(step - jerk, -change)
        motion += step
        travel += max(motion, 0.0)
    return travel


@jit()
def _ramped_speed(reach: float, last: float, jerk: float) -> float:
    """The largest motion m [rad] after a motion `last` whose speed-up, ramped down by `jerk`
    a period, never takes a period's motion past `reach`: m + Σ_i max(m − last − i·jerk, 0) ≤
    reach (bisection on m, whose peak grows with it)."""
    if _peak_motion(reach, last, jerk) <= reach:
        return reach
    low, high = min(last, reach), reach
    for _ in range(60):
        mid = 0.5 * (low + high)
        if _peak_motion(mid, last, jerk) <= reach:
            low = mid
        else:
            high = mid
    return low


@jit()
def _peak_motion(m: float, last: float, jerk: float) -> float:
    """The largest period's motion while a speed-up from `last` to m ramps down to zero at
    `jerk` a period."""
    rise = m - last
    if rise <= 0.0:
        return m
    k = math.floor(rise / jerk)
    return m + k * rise - jerk * k * (k + 1) / 2.0
