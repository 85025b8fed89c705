"""Collision geometry of a URDF: each link's <collision> elements as convex shapes."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Collection, Sequence
from pathlib import Path

import numpy as np
import trimesh

from articula.errors import ConfigError, GeometryError, ModelError
from articula.geometry.meshes import convex_parts, load_mesh
from articula.geometry.poses import pose
from articula.geometry.shapes import ConvexShape, box, convex_hull, cylinder, sphere
from articula.limits import MAX_DECOMPOSE_VERTICES

MAX_LINK_PARTS = 64  # more separate parts in one link mesh: noise, not a decomposition


def collision_shapes(
    urdf: Path, package_dirs: Sequence[Path] = (), decompose: bool | Collection[str] = False
) -> dict[str, list[tuple[ConvexShape, np.ndarray]]]:
    """Link name -> [(shape, pose of the shape in the link frame)] for every <collision>.

    Args:
        urdf: the URDF file.
        package_dirs: folders that hold the packages its package:// meshes name.
        decompose: which links' meshes CoACD decomposes into convex parts (cached on disk,
            see geometry.meshes.convex_parts) instead of one hull per separate part: True for
            every link, False for none, or link names (ConfigError "decompose" for a name the
            URDF has no link of).

    Returns:
        Each link's (convex shape, pose of the shape in the link frame, shape (4, 4) [m])
        pairs, by link name; links without <collision> are left out.
    """
    try:
        root = ET.parse(urdf).getroot()
    except (ET.ParseError, OSError) as exc:
        raise ModelError(f"{urdf}: cannot read URDF ({exc})") from None
    links = root.findall("link")
    chosen = _decomposed_links(decompose, [link.get("name", "") for link in links])
    shapes: dict[str, list[tuple[ConvexShape, np.ndarray]]] = {}
    for link in links:
        name = link.get("name", "")
        for i, element in enumerate(link.findall("collision")):
            geometry = element.find("geometry")
            if geometry is None or len(geometry) == 0:
                raise ModelError(f"{urdf}: link {name!r} has a <collision> without <geometry>")
            where = f"{urdf}: link {name!r} collision {i}"
            placement = origin(element.find("origin"), where)
            for shape in _shapes(geometry[0], urdf, package_dirs, where, name in chosen):
                shapes.setdefault(name, []).append((shape, placement))
    return shapes


def _decomposed_links(decompose: bool | Collection[str], names: Sequence[str]) -> set[str]:
    """The link names whose meshes are decomposed; ConfigError for a name of no link."""
    if isinstance(decompose, bool):
        return set(names) if decompose else set()
    # One string is one link name, not a collection of one-letter names.
    wanted = {decompose} if isinstance(decompose, str) else set(decompose)
    unknown = sorted(wanted - set(names))
    if unknown:
        raise ConfigError(
            "decompose", f"no link {', '.join(map(repr, unknown))}; the links are {list(names)}"
        )
    return wanted


def resolve_mesh_path(filename: str, urdf: Path, package_dirs: Sequence[Path]) -> Path:
    """File path of a URDF mesh reference: package://, file:// or relative to the URDF.

    Args:
        filename: the `filename` attribute of a <mesh> element.
        urdf: the URDF file that names the mesh.
        package_dirs: folders that hold the packages a package:// reference names.

    Returns:
        The mesh file's path (a package:// file is checked to exist; others are not).
    """
    if filename.startswith("package://"):
        package, _, rest = filename.removeprefix("package://").partition("/")
        candidates = [Path(d) / package / rest for d in package_dirs]
        candidates += [Path(d) / rest for d in package_dirs]
        candidates.append(urdf.parent / rest)
        for candidate in candidates:
            if candidate.is_file():
                return candidate
        raise GeometryError(
            f"{urdf}: cannot find {filename}; pass the folder that holds package "
            f"{package!r} in package_dirs"
        )
    if filename.startswith("file://"):
        return Path(filename.removeprefix("file://"))
    path = Path(filename)
    return path if path.is_absolute() else urdf.parent / path


def _shapes(
    element: ET.Element, urdf: Path, package_dirs: Sequence[Path], where: str, decompose: bool
) -> list[ConvexShape]:
    """The convex shapes of one <geometry> child: a mesh gives one per separate part, or its
    CoACD parts when `decompose`."""
    try:
        if element.tag == "mesh":
            path = resolve_mesh_path(element.get("filename", ""), urdf, package_dirs)
            scale = floats(element.get("scale", "1 1 1"), 3, where)
            mesh = load_mesh(path, scale)
            if decompose:
                if len(mesh.vertices) > MAX_DECOMPOSE_VERTICES:  # its run would take long
                    raise GeometryError(
                        f"{path.name} has {len(mesh.vertices):,} vertices, more than the "
                        f"{MAX_DECOMPOSE_VERTICES:,} a decomposition takes; simplify the mesh "
                        "or leave the link out of decompose"
                    )
                # The obstacles' decomposition and its disk cache: a mesh shared by links or
                # loaded again is decomposed once.
                return convex_parts(mesh, str(path), decompose=True)
            return mesh_parts(mesh, str(path))
        if element.tag == "box":
            return [box(floats(element.get("size", ""), 3, where))]
        if element.tag == "cylinder":
            return [
                cylinder(float(element.get("radius", "nan")), float(element.get("length", "nan")))
            ]
        if element.tag == "sphere":
            return [sphere(float(element.get("radius", "nan")))]
    except ValueError as exc:
        if isinstance(exc, GeometryError):
            raise GeometryError(f"{where}: {exc}") from None
        raise ModelError(f"{where}: {exc}") from None
    raise ModelError(
        f"{where}: unsupported geometry <{element.tag}>; use mesh, box, cylinder or sphere"
    )


def mesh_parts(mesh: trimesh.Trimesh, name: str) -> list[ConvexShape]:
    """One convex hull per separate part of a link mesh (a V-HACD file holds its convex
    pieces as separate parts; one hull over them all would fill the gaps between them), or
    the hull of the whole mesh when it is one part, has too many, or a part has no volume.

    Args:
        mesh: the link's triangle mesh [m].
        name: what the mesh is (its file), for error messages and the parts' names.

    Returns:
        The convex hulls, in the mesh's frame.
    """
    # No repair: hulls need only the vertices, and trimesh's hole filling needs networkx.
    pieces = mesh.split(only_watertight=False, repair=False)
    if 1 < len(pieces) <= MAX_LINK_PARTS:
        try:
            return [convex_hull(p.vertices, f"{name}[{i}]") for i, p in enumerate(pieces)]
        except GeometryError:
            pass  # a flat piece: its hull has no volume
    return [convex_hull(mesh.vertices, name)]


def origin(element: ET.Element | None, where: str) -> np.ndarray:
    """The pose (4×4) an <origin> element gives (identity without one).

    Args:
        element: the <origin> element (its xyz [m] and rpy [rad]), or None.
        where: the element's place in the URDF, for the error messages.

    Returns:
        The pose, shape (4, 4) [m].
    """
    if element is None:
        return np.eye(4)
    return pose(
        floats(element.get("xyz", "0 0 0"), 3, where),
        floats(element.get("rpy", "0 0 0"), 3, where),
    )


def floats(text: str, count: int, where: str) -> tuple[float, ...]:
    """`count` numbers from a URDF attribute; ModelError naming `where` otherwise.

    Args:
        text: the attribute's value, numbers separated by spaces.
        count: how many numbers it must hold.
        where: the attribute's place in the URDF, for the error messages.

    Returns:
        The numbers.
    """
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        raise ModelError(f"{where}: expected {count} numbers (got {text!r})") from None
    if len(values) != count:
        raise ModelError(f"{where}: expected {count} numbers (got {text!r})")
    return values
