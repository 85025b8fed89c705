"""The Arm interface: what a paced servo loop needs of an arm, simulated or real.

arm.connect()                    # -> the first measurement, the arm at rest
every 1 / arm.rate seconds:
    arm.send(q, qd)              # one set-point of the jerk-limited stream
    measured = arm.read()        # the joints and the arm's time of them
arm.stop()                       # bring it to rest within its limits
arm.close()
"""

from __future__ import annotations

from typing import NamedTuple, Protocol, runtime_checkable

import numpy as np

__all__ = ["Arm", "Measured"]


class Measured(NamedTuple):
    """The arm's joints as it measured them.

    Attributes:
        t: the arm's own time of the measurement [s] (its clock, not ours).
        q: joint positions, shape (n,) [rad], on the arm's own branch (a joint a turn
            off reads a turn off).
    """

    t: float
    q: np.ndarray


@runtime_checkable
class Arm(Protocol):
    """An arm that takes a stream of joint set-points at its servo rate.

    Attributes:
        rate: the servo rate the arm takes set-points at [Hz].
    """

    rate: float

    def connect(self) -> Measured:
        """Open the connection and start the arm's servo program.

        Returns:
            The first measurement (the arm has not moved yet).
        """
        ...

    def read(self) -> Measured:
        """The latest measurement.

        Returns:
            The joints and the arm's time of them.
        """
        ...

    def send(self, q: np.ndarray, qd: np.ndarray) -> None:
        """One set-point of the servo stream, for the next tick.

        Args:
            q: joint positions, shape (n,) [rad], on the arm's branch.
            qd: joint velocities, shape (n,) [rad/s].
        """
        ...

    def stop(self) -> None:
        """Bring the arm to rest within its limits (from wherever the stream left it) and
        stop its servo program."""
        ...

    def close(self) -> None:
        """Close the connection (after stop)."""
        ...
