"""The servo side of a drive: a thread that streams a plan's set-points to an arm at its rate.

The planner runs in the caller's thread at its own period and pushes one set-point per period
(`push`), up to `ahead` periods ahead; the loop turns each into that period's ticks of the
jerk-limited stream (loops.servo.ServoStream) and sends them paced by the wall clock
(arms.pacing.Pacer), reading the measured joints back after every tick (`latest`). The
planner's time is off the servo thread, so a slow step does not make a tick late; a set-point
missing at its period's start is a stall (the planner is more than `ahead` periods behind):
the loop then plays the stream's braking path, stops the arm and `push` raises StallError.
`finish` (the run's end) plays the queued set-points, then the same braking path; `stop`
(Ctrl-C, SIGTERM, a failure) plays it at once. The path's end is then held until the
measured arm, which lags its commands, is at rest too (REST, at most SETTLE), and only then
is the arm stopped.
"""

from __future__ import annotations

import threading
from collections import deque

import numpy as np

from articula.arms.arm import Arm, Measured
from articula.arms.pacing import Pacer
from articula.errors import ConfigError, DeviceError, StallError
from articula.loops.servo import ServoStream
from articula.robots.model import RobotModel

__all__ = ["AHEAD", "ServoLoop"]

AHEAD = 10  # [periods] how far the planner may run ahead of the stream (its stall bound)
PUSH_TIMEOUT = 5.0  # [s] a push that waits longer: the servo thread is wedged (a bug)
REST = 1e-3  # [rad/s] a measured joint slower than this is at rest
SETTLE = 1.0  # [s] the longest the braking path's end is held for the measured arm to rest


class ServoLoop:
    """Streams set-points to an arm on a thread of its own, paced at the arm's rate.

    Args:
        arm: the arm, connected.
        stream: the servo stream (its dt is the planner's period, its ticks the arm's rate).
        robot: the robot, for its continuous joints.
        start: the arm's first measurement; the stream starts at rest there.
        ahead: how many set-points the planner may queue before the stream plays them.

    Attributes:
        pacer: the ticks' pacer (their lateness).
        measured: every tick's measurement, the start's first.
        sent: every tick's set-point (n,) [rad] on the arm's branch.
        stalled: the loop ran out of set-points and braked.
        braked: the braking path was played and the arm stopped.
        error: what the arm raised, if it failed (the loop then ended).
        ended: set once the loop has ended (braked, stalled or failed).
    """

    def __init__(
        self,
        arm: Arm,
        stream: ServoStream,
        robot: RobotModel,
        start: Measured,
        ahead: int = AHEAD,
    ) -> None:
        if ahead < 1:
            raise ConfigError("ahead", f"must be ≥ 1 period (got {ahead})")
        self.arm, self.stream, self._robot, self._ahead = arm, stream, robot, ahead
        # A late tick restarts the schedule: a starved thread never sends ticks in a burst
        # (the stream slows rather than jumps; the lateness is still counted).
        self.pacer = Pacer(stream.dt / stream.ticks, catch_up=False)
        self.measured: list[Measured] = [start]
        self.sent: list[np.ndarray] = []
        self.stalled = self.braked = False
        self.error: BaseException | None = None
        self._last = np.array(start.q, dtype=float)  # the last set-point, on the arm's branch
        stream.reset(self._last)
        self._queue: deque[np.ndarray] = deque()
        self._stop = self._finished = False
        self._cv = threading.Condition()
        self.ended = threading.Event()
        self._thread = threading.Thread(target=self._run, name="servo", daemon=True)
        self._thread.start()

    def push(self, setpoint: np.ndarray) -> None:
        """Queue the next period's set-point; waits while `ahead` are queued.

        Args:
            setpoint: joint positions, shape (n,) [rad] (continuous joints any branch: they
                are streamed the short way round from the last one).

        Raises:
            StallError: the loop ran out of set-points and brought the arm to rest.
            DeviceError: the arm failed (the connection was lost).
        """
        robot = self._robot
        turned = self._last + robot.difference(np.asarray(setpoint, dtype=float), self._last)
        point = np.where(robot.continuous, turned, setpoint)
        with self._cv:
            if not self._cv.wait_for(self._room, PUSH_TIMEOUT):
                raise StallError(f"the servo loop took no set-point for {PUSH_TIMEOUT} s")
            self._raise_if_ended()
            self._queue.append(point)
            self._cv.notify_all()
        self._last = point

    def latest(self) -> Measured:
        """The last measurement.

        Returns:
            The joints (on the arm's branch) and the arm's time of them.
        """
        return self.measured[-1]

    def measurement(self) -> tuple[int, Measured]:
        """The last measurement and how far the stream was then.

        Returns:
            The whole periods the stream had played when it was taken, and the measurement.
        """
        ticks = len(self.measured) - 1
        return ticks // self.stream.ticks, self.measured[ticks]

    def finish(self) -> None:
        """No more set-points: play those queued, then the braking path, and stop the arm;
        returns when it is done. Raises the arm's failure, if it failed."""
        with self._cv:
            self._finished = True
            self._cv.notify_all()
        self._join()

    def stop(self) -> None:
        """Play the stream's braking path from where it is now (the queued set-points are
        dropped) and stop the arm; returns when it is done (also after a stall or a failure).
        Raises the arm's failure, if it failed."""
        with self._cv:
            self._stop = True
            self._cv.notify_all()
        self._join()

    def _join(self) -> None:
        self._thread.join()
        if self.error is not None:
            raise DeviceError(f"the arm failed: {self.error}") from self.error

    def _room(self) -> bool:
        return len(self._queue) < self._ahead or not self._thread.is_alive() or self._stop

    def _raise_if_ended(self) -> None:
        """Raise why the loop ended, if it did (called holding the lock)."""
        if self.error is not None:
            raise DeviceError(f"the arm failed: {self.error}") from self.error
        if self.stalled:
            raise StallError(
                f"the planner fell more than {self._ahead} periods of "
                f"{1e3 * self.stream.dt:g} ms behind the stream: the arm was brought to rest"
            )
        if self._stop or self._finished or not self._thread.is_alive():
            raise StallError("the servo loop has stopped")

    def _run(self) -> None:
        """The servo thread: wait for the first set-points, then one period after another,
        the braking path when they run out or stop() is asked."""
        try:
            with self._cv:
                self._cv.wait_for(
                    lambda: len(self._queue) >= self._ahead or self._stop or self._finished
                )
            while True:
                with self._cv:
                    if self._stop or not self._queue:
                        self.stalled = not (self._stop or self._finished)
                        break
                    point = self._queue.popleft()
                    self._cv.notify_all()
                self._play(self.stream.period(point))
            points = self.stream.stopping_points()
            for point in points:
                self._play(self.stream.period(point))
            for _ in range(int(np.ceil(SETTLE / self.stream.dt))):  # the measured arm lags
                if self._speed() <= REST:
                    break
                self._play(self.stream.period(points[-1]))
            self.arm.stop()
            self.braked = True
        except Exception as exc:  # the arm's failure ends the loop; push and stop raise it
            self.error = exc
        finally:
            self.ended.set()
            with self._cv:
                self._cv.notify_all()

    def _speed(self) -> float:
        """The largest joint speed between the last two measurements of different times."""
        last = self.measured[-1]
        for earlier in reversed(self.measured[:-1]):
            if earlier.t < last.t:
                return float(np.max(np.abs(last.q - earlier.q)) / (last.t - earlier.t))
        return 0.0

    def _play(self, samples: np.ndarray) -> None:
        """Send one period's ticks, each at its release, and read the arm back."""
        for q, qd, _ in samples:
            self.pacer.wait()
            self.arm.send(q, qd)
            self.sent.append(q)
            self.measured.append(self.arm.read())
