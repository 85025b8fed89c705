"""One exception root for articula; each subclass also inherits the matching built-in."""

from __future__ import annotations


class ArticulaError(Exception):
    """Root of every error articula raises on purpose."""


class ConfigError(ArticulaError, ValueError):
    """A configuration value is missing, unknown, of the wrong type or out of range.

    Args:
        field: where the value is: a config key path ("planner.d_min", with the file first
            when one is known), or a command-line option ("--out").
        problem: what is wrong with it and how to fix it.
    """

    def __init__(self, field: str, problem: str) -> None:
        self.field = field
        self.problem = problem
        self.loc: tuple[str, ...] | None = None  # path inside a config, when validation knows it
        super().__init__(f"{field}: {problem}")


class ModelError(ArticulaError, ValueError):
    """A physical model cannot be built from the given parameters."""


class GeometryError(ArticulaError, ValueError):
    """A shape or mesh cannot be used for distance queries."""


class InfeasibleError(ArticulaError, RuntimeError):
    """A requested operating point or plan cannot be reached within the limits.

    Args:
        problem: why it cannot be reached and what to change.
        field: the argument or config key whose value makes it infeasible; None: no one value.
    """

    def __init__(self, problem: str, field: str | None = None) -> None:
        self.field = field
        self.problem = problem
        super().__init__(f"{field}: {problem}" if field else problem)


class ResourceError(ArticulaError, OSError):
    """The machine, not the input, stops the work: a folder in use by another process, a full
    disk, an I/O error, too little memory. The command line exits with status 1 for it."""


class CollisionError(ArticulaError, RuntimeError):
    """A planned motion has colliding steps; its run folder is written, and the command line
    exits with status 4 unless collisions were allowed."""


class DeviceError(ArticulaError, OSError):
    """A bench rig or serial device failed or answered out of protocol."""


class PortError(ArticulaError, ValueError):
    """A rig's serial port cannot be used: it does not exist, nothing on it answers the
    handshake, or the device is another rig or speaks another protocol version (bad input:
    the command line exits with status 2; a rig failing mid-run is a DeviceError)."""


class StallError(ResourceError):
    """A servo loop ran out of set-points (the planner or the sender fell behind its bound):
    the arm was brought to rest and the run stopped. The command line exits with status 1."""
