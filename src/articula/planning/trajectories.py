"""Task-space reference paths x_r(t) [m]: circle (1.27), rectangle, waypoints, CSV."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from articula.errors import ConfigError


def _vector(name: str, value: Sequence[float], shape: tuple[int, ...]) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != shape or not np.all(np.isfinite(arr)):
        raise ConfigError(name, f"needs finite numbers of shape {shape} (got {arr.shape})")
    return arr


def _positive(name: str, value: float) -> float:
    if not (np.isfinite(value) and value > 0):
        raise ConfigError(name, f"must be a finite positive number (got {value})")
    return float(value)


@dataclass(frozen=True)
class Circle:
    """x_r(t) = C + r cos(2πt/T) A + r sin(2πt/T) B, Eq. (1.27); A, B orthonormal.

    Attributes:
        center: centre C, shape (3,) [m].
        axis_a: unit axis A, shape (3,).
        axis_b: unit axis B, perpendicular to A, shape (3,).
        radius: radius r [m].
        period: time T of one lap [s].
    """

    center: np.ndarray
    axis_a: np.ndarray
    axis_b: np.ndarray
    radius: float
    period: float

    @classmethod
    def create(
        cls,
        center: Sequence[float],
        axis_a: Sequence[float],
        axis_b: Sequence[float],
        radius: float,
        period: float,
    ) -> Circle:
        """A validated circle: A and B must be perpendicular unit vectors.

        Args:
            center: centre C, shape (3,) [m].
            axis_a: unit axis A, shape (3,).
            axis_b: unit axis B, perpendicular to A, shape (3,).
            radius: radius r, > 0 [m].
            period: time T of one lap, > 0 [s].

        Returns:
            The circle.
        """
        a = _vector("axis_a", axis_a, (3,))
        b = _vector("axis_b", axis_b, (3,))
        if not (np.isclose(a @ a, 1) and np.isclose(b @ b, 1) and abs(a @ b) < 1e-9):
            raise ConfigError("axis_b", "axis_a and axis_b must be perpendicular unit vectors")
        center_ = _vector("center", center, (3,))
        radius_ = _positive("radius", radius)
        return cls(center_, a, b, radius_, _positive("period", period))

    def __call__(self, t: float) -> np.ndarray:
        """Reference point [m] at time t [s]."""
        phase = 2.0 * np.pi * t / self.period
        return self.center + self.radius * (
            np.cos(phase) * self.axis_a + np.sin(phase) * self.axis_b
        )  # Eq. (1.27)


@dataclass(frozen=True)
class Waypoints:
    """Straight lines between points [m] reached at increasing times [s]; held after the last.

    Attributes:
        points: the waypoints, shape (k, 3) [m].
        times: when each is reached, strictly increasing, shape (k,) [s].
    """

    points: np.ndarray
    times: np.ndarray

    @classmethod
    def create(cls, points: Sequence[Sequence[float]], times: Sequence[float]) -> Waypoints:
        """Validated waypoints: at least two, finite, times strictly increasing.

        Args:
            points: the waypoints, shape (k, 3) [m].
            times: when each is reached, shape (k,) [s].

        Returns:
            The waypoints.
        """
        p = np.asarray(points, dtype=float)
        t = np.asarray(times, dtype=float)
        if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
            raise ConfigError("points", f"needs two or more [x, y, z] (got {p.shape})")
        if t.shape != (len(p),):
            raise ConfigError("times", f"needs {len(p)} times, one per point")
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(t))):
            raise ConfigError("points", "points and times must be finite numbers")
        if np.any(np.diff(t) <= 0):
            raise ConfigError("times", "must be strictly increasing")
        return cls(p, t)

    @classmethod
    def from_csv(cls, path: Path) -> Waypoints:
        """Waypoints from a CSV file with the header t,x,y,z (and optionally an orientation
        per row, see read_csv).

        Args:
            path: the CSV file.

        Returns:
            The waypoints of its rows.
        """
        data = read_csv(path)
        return cls.create(np.column_stack([data["x"], data["y"], data["z"]]), data["t"])

    def __call__(self, t: float) -> np.ndarray:
        """Reference point [m] at time t [s]."""
        return np.array([np.interp(t, self.times, self.points[:, i]) for i in range(3)])


CSV_ORIENTATIONS = ({"roll", "pitch", "yaw"}, {"qw", "qx", "qy", "qz"})


def read_csv(path: Path) -> np.ndarray:
    """The rows of a trajectory CSV as a structured array: columns t, x, y, z [s, m], and
    optionally roll, pitch, yaw [rad] or qw, qx, qy, qz (the tool's orientation per row).

    Args:
        path: the CSV file, with a header row.

    Returns:
        The rows, as a structured array with one named field per column.
    """
    if not Path(path).is_file():
        raise ConfigError("path", f"{path}: file not found")
    try:
        data = np.genfromtxt(path, delimiter=",", names=True)
    except ValueError as exc:
        raise ConfigError("path", f"{path}: not a numeric CSV ({exc})") from None
    names = set(data.dtype.names or ())
    if not any(names in ({"t", "x", "y", "z"}, {"t", "x", "y", "z"} | o) for o in CSV_ORIENTATIONS):
        raise ConfigError(
            "path",
            f"{path}: needs columns t, x, y, z, optionally with roll, pitch, yaw or qw, qx, qy, "
            f"qz (got {sorted(names)})",
        )
    return np.atleast_1d(data)


def rectangle(vertices: Sequence[Sequence[float]], period: float) -> Waypoints:
    """The closed path through four vertices at constant speed, once per `period`.

    Args:
        vertices: the four corners in order, shape (4, 3) [m].
        period: time of one lap [s].

    Returns:
        The path as waypoints, back at the first vertex after one period.
    """
    v = _vector("vertices", vertices, (4, 3))
    T = _positive("period", period)
    loop = np.vstack([v, v[:1]])
    lengths = np.linalg.norm(np.diff(loop, axis=0), axis=1)
    if np.any(lengths <= 0):
        raise ConfigError("vertices", "consecutive vertices must differ")
    times = np.concatenate([[0.0], np.cumsum(lengths)]) / lengths.sum() * T
    return Waypoints.create(loop, times)
