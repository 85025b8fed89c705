"""The visual geometry a URDF gives its links: what a viewer draws (the collision shapes are
what distances use; robots/urdf_geometry.py)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from articula.errors import GeometryError, ModelError
from articula.geometry.meshes import load_mesh
from articula.robots.urdf_geometry import floats, origin, resolve_mesh_path


@dataclass(frozen=True)
class Visual:
    """One <visual> of a link: its mesh [m], pose in the link frame (4×4) and colour (RGBA in
    0-1, None when the URDF gives none).

    Attributes:
        mesh: the visual's triangle mesh, in its own frame [m].
        placement: pose of the mesh in the link frame, shape (4, 4) [m].
        rgba: colour as red, green, blue, alpha in 0-1, or None when the URDF gives none.
    """

    mesh: trimesh.Trimesh
    placement: np.ndarray
    rgba: tuple[float, float, float, float] | None


def visual_meshes(urdf: Path, package_dirs: Sequence[Path] = ()) -> dict[str, list[Visual]]:
    """Link name -> its visuals (mesh files, boxes, cylinders, spheres), in URDF order.

    Raises ModelError (or GeometryError for a mesh file) when the URDF or a visual cannot be
    read; a viewer then draws the collision shapes instead.

    Args:
        urdf: the URDF file.
        package_dirs: folders that hold the packages its package:// meshes name.

    Returns:
        Each link's visuals, by link name; links without <visual> are left out.
    """
    try:
        root = ET.parse(urdf).getroot()
    except (ET.ParseError, OSError) as exc:
        raise ModelError(f"{urdf}: cannot read URDF ({exc})") from None
    colours = {m.get("name", ""): _rgba(m) for m in root.findall("material")}
    out: dict[str, list[Visual]] = {}
    for link in root.findall("link"):
        name = link.get("name", "")
        for i, element in enumerate(link.findall("visual")):
            where = f"{urdf}: link {name!r} visual {i}"
            geometry = element.find("geometry")
            if geometry is None or len(geometry) == 0:
                raise ModelError(f"{where}: no <geometry>")
            material = element.find("material")
            rgba = None
            if material is not None:
                rgba = _rgba(material) or colours.get(material.get("name", ""))
            mesh = _mesh(geometry[0], urdf, package_dirs, where)
            out.setdefault(name, []).append(
                Visual(mesh, origin(element.find("origin"), where), rgba)
            )
    return out


def _mesh(
    element: ET.Element, urdf: Path, package_dirs: Sequence[Path], where: str
) -> trimesh.Trimesh:
    """The triangle mesh of one <geometry> child [m]."""
    try:
        if element.tag == "mesh":
            path = resolve_mesh_path(element.get("filename", ""), urdf, package_dirs)
            return load_mesh(path, floats(element.get("scale", "1 1 1"), 3, where))
        if element.tag == "box":
            return trimesh.creation.box(extents=floats(element.get("size", ""), 3, where))
        if element.tag == "cylinder":
            radius, length = (
                float(element.get("radius", "nan")),
                float(element.get("length", "nan")),
            )
            return trimesh.creation.cylinder(radius=radius, height=length, sections=32)
        if element.tag == "sphere":
            return trimesh.creation.icosphere(
                subdivisions=2, radius=float(element.get("radius", "nan"))
            )
    except (ValueError, GeometryError) as exc:
        raise ModelError(f"{where}: {exc}") from None
    raise ModelError(f"{where}: unsupported geometry <{element.tag}>")


def _rgba(material: ET.Element) -> tuple[float, float, float, float] | None:
    """A <material>'s <color rgba="..."> in 0-1, or None."""
    colour = material.find("color")
    if colour is None:
        return None
    try:
        values = tuple(float(v) for v in colour.get("rgba", "").split())
    except ValueError:
        return None
    return values if len(values) == 4 else None  # type: ignore[return-value]
