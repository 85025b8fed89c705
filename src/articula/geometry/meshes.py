"""Mesh files (STL, OBJ, PLY, DAE) to convex parts: hull by default, decomposition on request."""

from __future__ import annotations

import hashlib
import io
from pathlib import Path

import numpy as np
import trimesh

from articula.disk_cache import keep, read_cached
from articula.errors import GeometryError
from articula.geometry.shapes import ConvexShape, convex_hull
from articula.limits import MAX_DECOMPOSE_VERTICES, MAX_LENGTH, MAX_SCALE, MIN_SCALE

FORMATS = (".stl", ".obj", ".ply", ".dae")


def load_mesh(path: Path, scale: float | tuple[float, float, float] = 1.0) -> trimesh.Trimesh:
    """Read a mesh file into one triangle mesh [m], scaled; GeometryError for unusable files.

    Scenes and multi-body files are merged into one mesh. Not being watertight is accepted:
    distances use convex hulls, which need only the vertices.

    Args:
        path: the mesh file (.stl, .obj, .ply or .dae).
        scale: factor from the file's units to metres, one for all axes or one per axis
            (x, y, z), as in a URDF `<mesh scale>`.

    Returns:
        The scaled triangle mesh [m], duplicate vertices merged.
    """
    path = Path(path)
    if not path.is_file():
        raise GeometryError(f"{path}: mesh file not found")
    if path.suffix.lower() not in FORMATS:
        raise GeometryError(f"{path}: unsupported mesh format; use one of {', '.join(FORMATS)}")
    try:
        loaded = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for corrupt files
        raise GeometryError(f"{path}: cannot read mesh ({type(exc).__name__}: {exc})") from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.vertices) == 0:
        raise GeometryError(f"{path}: the file holds no vertices")
    vertices = np.asarray(loaded.vertices, dtype=float)
    if not np.all(np.isfinite(vertices)):
        raise GeometryError(f"{path}: vertices contain NaN or infinite values")
    factor = np.broadcast_to(np.asarray(scale, dtype=float), (3,))
    if not np.all((np.abs(factor) >= MIN_SCALE) & (np.abs(factor) <= MAX_SCALE)):
        raise GeometryError(
            f"{path}: scale must be within ±[{MIN_SCALE:g}, {MAX_SCALE:g}] (got {scale})"
        )
    scaled = vertices * factor
    if not np.all(np.abs(scaled) <= MAX_LENGTH):
        raise GeometryError(
            f"{path}: scaled vertices reach {np.abs(scaled).max():.3g} m, beyond ±{MAX_LENGTH:g} "
            "m; check the scale and the file's units"
        )
    # Processing merges the duplicate corners of STL triangle soups into a connected mesh.
    return trimesh.Trimesh(scaled, np.asarray(loaded.faces), process=True)


def convex_parts(
    mesh: trimesh.Trimesh,
    name: str,
    decompose: bool = False,
    threshold: float = 0.05,
    max_vertices: int = MAX_DECOMPOSE_VERTICES,
) -> list[ConvexShape]:
    """Convex pieces standing for `mesh`: its hull, or a CoACD decomposition when `decompose`.

    The hull is conservative (every point of the mesh is inside it). The decomposition follows
    concavities more tightly, to within `threshold` (CoACD's concavity bound, relative); it
    refuses a mesh of more than `max_vertices` vertices, whose decomposition would run for long.

    Args:
        mesh: the triangle mesh to approximate [m].
        name: what the mesh is (e.g. its file), for the error messages and the parts' names.
        decompose: whether to split the mesh into convex parts with CoACD instead of one hull.
        threshold: CoACD's concavity bound, relative to the mesh size, in (0, 1].
        max_vertices: largest mesh, in vertices, that a decomposition accepts.

    Returns:
        The convex parts, in the mesh's frame: one hull, or one per decomposed piece.
    """
    if not decompose:
        return [convex_hull(mesh.vertices, name)]
    if len(mesh.vertices) > max_vertices:
        raise GeometryError(
            f"{name}: {len(mesh.vertices):,} vertices are more than the {max_vertices:,} a "
            f"decomposition takes; simplify the mesh, or raise max_vertices (to "
            f"{len(mesh.vertices)}) and expect a long run"
        )
    try:
        import coacd
    except ImportError:
        raise GeometryError(f"{name}: decomposition needs the coacd package") from None
    if not (0 < threshold <= 1):
        raise GeometryError(f"{name}: threshold must be in (0, 1] (got {threshold})")
    vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
    key = _cache_key(vertices, faces, threshold)
    pieces = _cached(key)
    if pieces is None:
        coacd.set_log_level("error")
        # CoACD repairs non-manifold input itself ("manifold" preprocessing); its seed is fixed
        # so that the same file always gives the same parts.
        parts = coacd.run_coacd(
            coacd.Mesh(vertices, faces), threshold=threshold, preprocess_mode="auto", seed=0
        )
        pieces = [np.asarray(v, dtype=float) for v, _ in parts]
        _store(key, pieces)
    return [convex_hull(v, f"{name}[{i}]") for i, v in enumerate(pieces)]


def _cache_key(vertices: np.ndarray, faces: np.ndarray, threshold: float) -> str:
    """A decomposition's name: the mesh's content, the threshold and CoACD's version."""
    import coacd

    digest = hashlib.sha256(vertices.tobytes() + faces.astype(np.int64).tobytes())
    digest.update(f"{threshold!r}/{getattr(coacd, '__version__', '?')}".encode())
    return digest.hexdigest()


def _cached(key: str) -> list[np.ndarray] | None:
    """The parts' vertices [m] of a decomposition made before, or None."""
    data = read_cached(f"{key}.npz")
    if data is None:
        return None
    try:
        with np.load(io.BytesIO(data)) as parts:
            return [parts[f"part{i}"] for i in range(len(parts.files))]
    except (OSError, ValueError, KeyError):
        return None  # unreadable: decompose again


def _store(key: str, pieces: list[np.ndarray]) -> None:
    """Keep a decomposition for next time (written whole, or not at all)."""
    buffer = io.BytesIO()
    np.savez(buffer, **{f"part{i}": v for i, v in enumerate(pieces)})
    keep(f"{key}.npz", buffer.getvalue())
