"""The arm, path and scenes shared by the planning tests: the iiwa14, the book's circle (Eq. 1.27)
and a ball in front of a bent arm; checks of a tracking run."""

from __future__ import annotations

import numpy as np

from articula.geometry.poses import pose
from articula.geometry.shapes import sphere
from articula.loops.tracking import track
from articula.planning.planner import Planner
from articula.planning.trajectories import Circle
from articula.robots import RobotModel
from articula.scene import Obstacle, Scene

ROBOT = RobotModel.builtin("iiwa14")
FREE = Scene(ROBOT, [])
CIRCLE = Circle.create([0.0, 0.6, 0.5], [1, 0, 0], [0, 0, 1], 0.2, 50.0)  # the book's circle
DT = 0.01  # [s] control period
# A bent arm and a ball in front of it: every link from the third on is within 0.3 m.
Q_BENT = np.array([0.1, 0.4, 0.0, -1.0, 0.0, 0.5, 0.0])


def ball(center, radius: float) -> Scene:
    """The iiwa14 and one ball of `radius` [m] at `center` [m]."""
    return Scene(ROBOT, [Obstacle("ball", (sphere(radius),), pose(center))])


def rms_after(result, settle: float) -> float:
    """RMS tracking error [m] of a run after `settle` [s]."""
    return float(np.sqrt(np.mean(result.error[result.t >= settle] ** 2)))


def assert_tracks_the_circle_within_limits(planner: Planner) -> None:
    """From q = 0, the planner reaches the book circle to under 1 mm within 3 s, moving fast on
    the approach but within the joint speed and position limits, one iteration per period."""
    q0 = np.zeros(ROBOT.nq)
    r = track(planner, CIRCLE, q0, DT, 6.0)
    assert r.error[0] > 0.1  # q = 0 is far from the circle
    late = r.error[r.t >= 3.0]
    assert late.max() < 1e-3  # sub-millimetre once settled
    speeds = np.abs(np.diff(np.vstack([q0, r.q]), axis=0)) / DT
    assert np.all(speeds <= ROBOT.velocity_limit * (1 + 1e-9) + 1e-12)
    assert speeds.max() > 0.5 * ROBOT.velocity_limit.min()  # it did move fast on the approach
    assert np.all(r.q >= ROBOT.lower) and np.all(r.q <= ROBOT.upper)
    assert planner.iterations == len(r.t)
