"""Scenes shared by the scene and planning tests: the book's chapter-1 scene files, and one shape
on a one-joint robot against one obstacle, with the poses written out by hand."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from articula.geometry.shapes import ConvexShape
from articula.robots.model import LinkGeometry, RobotModel
from articula.scene import Obstacle, Scene
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

# The packaged chapter-1 scene files (data only: library tests do not import articula.book).
CONFIGS = Path(__file__).resolve().parents[2] / "src/articula/book/ch1/configs"


def book_scene(name: str, self_collision: bool = False) -> Scene:
    """A new Scene built from the chapter-1 scene file `name` (e.g. "circle_two_obstacles"),
    by default without self pairs (link-obstacle distances alone)."""
    path = CONFIGS / f"{name}.toml"
    data = load_toml(path)
    data["robot"]["self_collision"] = self_collision
    return build_scene(load_scene_spec(data), path.parent)[0]


def one_link_robot(shapes: list[ConvexShape], placements: list[np.ndarray]) -> RobotModel:
    """A robot whose single link (on a prismatic z joint, q = 0 at rest) carries `shapes`."""
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelPZ(), pin.SE3.Identity(), "slide")
    model.lowerPositionLimit[:] = -1.0
    model.upperPositionLimit[:] = 1.0
    joint_frame = model.addJointFrame(joint, 0)
    frame = model.addBodyFrame("link", joint, pin.SE3.Identity(), joint_frame)
    link = LinkGeometry("link", frame, tuple(shapes), tuple(placements))
    return RobotModel(model, [link], "link")


def pair_scene(a: ConvexShape, Ta: np.ndarray, b: ConvexShape, Tb: np.ndarray) -> Scene:
    """Shape a on the robot link at pose Ta (q = 0), shape b as a static obstacle at pose Tb."""
    return Scene(one_link_robot([a], [Ta]), [Obstacle("b", (b,), Tb)])


def signed(a: ConvexShape, Ta: np.ndarray, b: ConvexShape, Tb: np.ndarray) -> float:
    """The scene's signed distance [m] between shape a at pose Ta and shape b at pose Tb."""
    return float(pair_scene(a, Ta, b, Tb).distances([0.0])[0, 0])


def rigid(R: np.ndarray, p) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def world(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    return points @ T[:3, :3].T + T[:3, 3]


def box_signed_distance(point: np.ndarray, half: np.ndarray) -> float:
    """Signed distance [m] of a point (in the box frame) to a box of half-sizes `half`."""
    q = np.abs(point) - half
    return float(np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0))
