"""Independent oracles: trace-based time-response metrics for the loop's streaming metrics;
clearances by coal on the convex hulls of a URDF's own collision meshes."""

from __future__ import annotations

from pathlib import Path
from typing import Any
from xml.etree import ElementTree

import numpy as np


def rise_time(t: np.ndarray, y: np.ndarray, start: float, target: float) -> np.ndarray:
    """10–90 % rise time [s] of each row of y from `start` to `target`; NaN if never reached."""
    y = np.atleast_2d(y)
    span = target - start
    frac = (y - start) / span if span != 0 else np.full(y.shape, np.nan)
    t10 = _first_time(t, frac >= 0.1)
    t90 = _first_time(t, frac >= 0.9)
    return t90 - t10


def sinusoid_fit(t: np.ndarray, y: np.ndarray, frequency: float) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares amplitude and phase [rad] of y ≈ c + A·sin(ω t + φ) for each row of y."""
    X = np.column_stack([np.ones_like(t), np.sin(frequency * t), np.cos(frequency * t)])
    coef, *_ = np.linalg.lstsq(X, np.atleast_2d(y).T, rcond=None)
    a_sin, a_cos = coef[1], coef[2]
    return np.hypot(a_sin, a_cos), np.arctan2(a_cos, a_sin)


def _first_time(t: np.ndarray, hit: np.ndarray) -> np.ndarray:
    """Time of the first True in each row; NaN where a row has none."""
    idx = hit.argmax(axis=1)
    return np.where(hit.any(axis=1), t[idx], np.nan)


def urdf_hull_clearances(
    urdf: str,
    package_dirs: list[str],
    joint_names: list[str],
    qs: np.ndarray,
    obstacles: list[tuple[Any, np.ndarray]],
    pairs: list[tuple[str, str]],
) -> tuple[float, float]:
    """The smallest link–obstacle and link–link distances over qs, by coal on the convex hulls
    of the URDF's own collision meshes (trimesh), placed by Pinocchio's forward kinematics of
    the URDF: an implementation that shares nothing with articula's Scene.

    Args:
        urdf: the URDF file; its meshes as package:// paths under package_dirs or relative.
        package_dirs: folders package:// paths start from.
        joint_names: the joints of each row of qs, by name (the others at 0).
        qs: joint positions, shape (m, len(joint_names)) [rad].
        obstacles: (coal shape, 4×4 pose in the world) of each obstacle part.
        pairs: the link pairs whose distance counts, by link name.

    Returns:
        (obstacle clearance, self clearance) [m]; inf where there is nothing to measure.
    """
    import coal
    import pinocchio as pin
    import trimesh
    from scipy.spatial.transform import Rotation

    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    hulls: dict[str, list[tuple[Any, np.ndarray]]] = {}
    for link in ElementTree.parse(urdf).getroot().iter("link"):
        for collision in link.iter("collision"):
            mesh = collision.find("geometry/mesh")
            if mesh is None:
                continue  # the arms tested here have meshes only
            path = _resolve(mesh.get("filename"), Path(urdf).parent, package_dirs)
            scale = np.array([float(v) for v in mesh.get("scale", "1 1 1").split()])
            vertices = trimesh.load(path, force="mesh").convex_hull.vertices * scale
            points = coal.StdVec_Vec3s()
            points.extend(list(vertices))
            origin = collision.find("origin")
            T = np.eye(4)
            if origin is not None:
                T[:3, 3] = [float(v) for v in origin.get("xyz", "0 0 0").split()]
                rpy = [float(v) for v in origin.get("rpy", "0 0 0").split()]
                T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
            hull = coal.Convex.convexHull(points, False, None)
            hulls.setdefault(link.get("name"), []).append((hull, T))
    frames = {name: model.getFrameId(name) for name in hulls}
    index = [model.idx_qs[model.getJointId(name)] for name in joint_names]
    request = coal.DistanceRequest()
    placed = {}
    obstacle = self_ = np.inf
    for q in qs:
        q_full = pin.neutral(model)
        q_full[index] = q
        pin.framesForwardKinematics(model, data, q_full)
        for name, shapes in hulls.items():
            oMf = data.oMf[frames[name]].homogeneous
            placed[name] = [(hull, _transform(oMf @ T)) for hull, T in shapes]
        for shapes in placed.values():
            for hull, pose in shapes:
                for shape, T in obstacles:
                    d = coal.distance(
                        hull, pose, shape, _transform(T), request, coal.DistanceResult()
                    )
                    obstacle = min(obstacle, d)
        for a, b in pairs:
            for hull_a, pose_a in placed.get(a, []):
                for hull_b, pose_b in placed.get(b, []):
                    d = coal.distance(
                        hull_a, pose_a, hull_b, pose_b, request, coal.DistanceResult()
                    )
                    self_ = min(self_, d)
    return obstacle, self_


def _resolve(filename: str, folder: Path, package_dirs: list[str]) -> Path:
    """A URDF mesh path as a file: package://... under one of package_dirs, else relative."""
    if filename.startswith("package://"):
        rest = filename.removeprefix("package://")
        for base in package_dirs:
            if (Path(base) / rest).exists():
                return Path(base) / rest
        raise FileNotFoundError(filename)
    return folder / filename


def _transform(T: np.ndarray) -> Any:
    """A 4×4 pose as coal's Transform3s."""
    import coal

    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))
