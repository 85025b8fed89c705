"""Build the iiwa14 collision hulls shipped in src/articula/robots/data/iiwa14/ (developer tool).

    pip download --no-deps pybullet -d /tmp/pyb
    python tools/build_iiwa14.py /tmp/pyb/pybullet-*.whl

Reads the BSD-licensed lbr_iiwa link meshes (pybullet_data/kuka_iiwa/meshes/link_*.stl) from
the wheel, takes each convex hull, simplifies it only outward (an intersection of supporting
half-spaces, so every original vertex stays inside), and writes:
  - src/articula/robots/data/iiwa14/meshes/link_<k>.stl (the hulls)
  - tests/data/iiwa14_mesh_vertices.npz (the original vertices, for the containment test)
It prints, per link, the vertex counts and how far the simplified hull reaches beyond the
exact one. Nothing in the package runs this; it needs scipy, trimesh and the wheel only.
"""

from __future__ import annotations

import argparse
import io
import zipfile
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial import ConvexHull, HalfspaceIntersection

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "src/articula/robots/data/iiwa14/meshes"
VERTICES = ROOT / "tests/data/iiwa14_mesh_vertices.npz"
MAX_PLANES = 60
PAD = 1e-6  # [m]


def outward_hull(points: np.ndarray, planes: int = MAX_PLANES) -> np.ndarray:
    """Vertices of a convex polytope with at most `planes` faces that contains `points`.

    The exact hull's facets are grouped by normal (area-weighted k-means on the sphere); each
    group becomes one supporting plane at the largest projection of any point, so all points
    stay inside, and the planes' intersection is the simplified hull.
    """
    hull = ConvexHull(points)
    normals = hull.equations[:, :3]
    if len(normals) <= planes:
        return points[hull.vertices]
    areas = np.array([_triangle_area(points[s]) for s in hull.simplices])
    rng = np.random.default_rng(0)
    centers = normals[rng.choice(len(normals), planes, replace=False, p=areas / areas.sum())]
    for _ in range(50):
        label = np.argmax(normals @ centers.T, axis=1)
        for j in range(planes):
            members = label == j
            if members.any():
                c = (normals[members] * areas[members, None]).sum(axis=0)
                centers[j] = c / np.linalg.norm(c)
    axes = np.vstack([np.eye(3), -np.eye(3)])  # keep the bounding box tight
    directions = np.vstack([centers, axes])
    # 1 µm of padding keeps every vertex inside once the corners are rounded to float32 (STL).
    offsets = (points @ directions.T).max(axis=0) + PAD
    interior = points[hull.vertices].mean(axis=0)
    halfspaces = np.hstack([directions, -offsets[:, None]])
    corners = HalfspaceIntersection(halfspaces, interior).intersections
    return corners[ConvexHull(corners).vertices]


def _triangle_area(tri: np.ndarray) -> float:
    return 0.5 * float(np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0])))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("wheel", type=Path, help="pybullet wheel (.whl)")
    args = parser.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    originals = {}
    with zipfile.ZipFile(args.wheel) as wheel:
        for k in range(8):
            data = wheel.read(f"pybullet_data/kuka_iiwa/meshes/link_{k}.stl")
            mesh = trimesh.load(io.BytesIO(data), file_type="stl")
            points = np.unique(np.asarray(mesh.vertices), axis=0)
            originals[f"link_{k}"] = points.astype(np.float64)
            simplified = trimesh.convex.convex_hull(outward_hull(points))
            simplified.export(OUT / f"link_{k}.stl")
            exact = trimesh.convex.convex_hull(points)
            _, reach, _ = trimesh.proximity.closest_point_naive(exact, simplified.vertices)
            print(
                f"link_{k}: {len(points)} mesh vertices, exact hull {len(exact.vertices)}, "
                f"shipped hull {len(simplified.vertices)} vertices, reaches at most "
                f"{1e3 * float(np.max(reach)):.1f} mm beyond the exact hull"
            )
    np.savez_compressed(VERTICES, **originals)


if __name__ == "__main__":
    main()
