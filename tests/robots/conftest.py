"""Fixtures of the robot tests: the small URDF written out with its meshes, and built edited."""

from __future__ import annotations

import pytest
import trimesh

from articula.robots import RobotModel
from tests.robots.helpers import SMALL_URDF


@pytest.fixture
def small_arm(tmp_path) -> dict:
    """Write the small URDF, its meshes (STL, OBJ in a package, DAE) and return the paths."""
    (tmp_path / "meshes").mkdir()
    a = trimesh.creation.box(extents=(0.1, 0.04, 0.06))
    a.export(tmp_path / "meshes/a.stl")
    pkg = tmp_path / "pkgs"
    (pkg / "mypkg/meshes").mkdir(parents=True)
    b = trimesh.creation.icosphere(subdivisions=1, radius=0.04)
    b.apply_translation([0.01, 0.0, 0.0])
    b.export(pkg / "mypkg/meshes/b.obj")
    c = trimesh.creation.cylinder(radius=0.02, height=0.1, sections=12)
    c.export(tmp_path / "c.dae")
    urdf = tmp_path / "small.urdf"
    urdf.write_text(SMALL_URDF)
    return {"urdf": urdf, "pkg": pkg, "a": a, "b": b, "c": c}


@pytest.fixture
def build_edited(small_arm):
    """build_edited(old, new): the small arm built from its URDF with `old` replaced by `new`."""

    def build(old: str, new: str) -> RobotModel:
        urdf = small_arm["urdf"]
        urdf.write_text(SMALL_URDF.replace(old, new))
        return RobotModel.from_urdf(urdf, [small_arm["pkg"]])

    return build
