"""What the viewer puts in a viser scene: links, obstacles, paths, the closest pair; and the
colour of a link by its clearance."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import trimesh
import viser

from articula.robots.urdf_visuals import Visual
from articula.scene.scene import Scene

ROBOT_COLOUR = (255, 140, 0)  # orange: what the browser tests look for
OBSTACLE_COLOUR = (120, 120, 130)
REFERENCE_COLOUR = (40, 110, 230)
PATH_COLOUR = (20, 170, 60)
CLOSEST_COLOUR = (220, 30, 30)
NEAR = 0.05  # [m] a link closer than this to an obstacle is shaded toward red
CAMERA = (1.6, -1.6, 1.3)  # [m] where a new tab's camera starts, looking at LOOK_AT
LOOK_AT = (0.0, 0.0, 0.5)


def aim_camera(server: viser.ViserServer) -> None:
    """New tabs look at an arm on the origin from the front right, about 2.5 m away.

    Args:
        server: the viser server whose initial camera is set.
    """
    server.initial_camera.position = CAMERA
    server.initial_camera.look_at = LOOK_AT


def wxyz_position(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """viser's (quaternion w, x, y, z; position) of a 4×4 pose (Pinocchio's conversion: a
    live page converts a dozen poses every 10 ms, scipy's takes ~0.2 ms each).

    Args:
        T: a homogeneous transform, shape (4, 4) [m].

    Returns:
        Its unit quaternion (w, x, y, z), shape (4,), and position, shape (3,) [m].
    """
    x, y, z, w = pin.Quaternion(np.ascontiguousarray(T[:3, :3])).coeffs()
    return np.array([w, x, y, z]), T[:3, 3].copy()


def clearance_colour(d: float, d_min: float) -> tuple[int, int, int]:
    """The robot's colour far from obstacles, shading to red at d_min (and red below).

    Args:
        d: the link's clearance to the nearest obstacle [m] (inf: no obstacle).
        d_min: the planner's safety distance [m].

    Returns:
        The colour (r, g, b), 0-255 each: orange from NEAR up, red at d_min and below.
    """
    if not np.isfinite(d) or d >= NEAR:
        return ROBOT_COLOUR
    s = float(np.clip((d - d_min) / max(NEAR - d_min, 1e-9), 0.0, 1.0))
    red = np.array(CLOSEST_COLOUR)
    return tuple(int(v) for v in red + s * (np.array(ROBOT_COLOUR) - red))  # type: ignore[return-value]


def add_robot(
    server: viser.ViserServer,
    visuals: dict[str, list[Visual]],
    root: str = "/robot",
    colour: tuple[int, int, int] = ROBOT_COLOUR,
    opacity: float | None = None,
) -> tuple[dict[str, viser.FrameHandle], dict[str, list]]:
    """A frame per link (<root>/<link>) with its meshes; (frames, meshes) by link name.

    Args:
        server: the viser server to draw in.
        visuals: link name -> its meshes and their poses in the link frame.
        root: the scene node the arm is drawn under (a second arm needs its own).
        colour: the meshes' colour (RGB, 0-255).
        opacity: the meshes' opacity, 0-1; None: opaque.

    Returns:
        The link frames (posed to move the link) and each link's mesh handles (recoloured
        by clearance), by link name.
    """
    frames, meshes = {}, {}
    for link, items in visuals.items():
        frames[link] = server.scene.add_frame(f"{root}/{link}", show_axes=False)
        meshes[link] = []
        for i, visual in enumerate(items):
            wxyz, position = wxyz_position(visual.placement)
            meshes[link].append(
                server.scene.add_mesh_simple(
                    f"{root}/{link}/visual_{i}",
                    np.asarray(visual.mesh.vertices, dtype=np.float32),
                    np.asarray(visual.mesh.faces, dtype=np.uint32),
                    color=colour,
                    opacity=opacity,
                    wxyz=wxyz,
                    position=position,
                )
            )
    return frames, meshes


def add_obstacles(
    server: viser.ViserServer, scene: Scene, t: float
) -> dict[str, viser.FrameHandle]:
    """A frame per obstacle (/obstacles/<name>) at its pose at time t, with its convex
    parts.

    Args:
        server: the viser server to draw in.
        scene: the scene whose obstacles are drawn.
        t: the time the obstacles are posed at [s].

    Returns:
        The obstacles' frames by obstacle name.
    """
    frames = {}
    for obstacle in scene.obstacles:
        wxyz, position = wxyz_position(obstacle.pose_at(t))
        frames[obstacle.name] = server.scene.add_frame(
            f"/obstacles/{obstacle.name}", show_axes=False, wxyz=wxyz, position=position
        )
    add_obstacle_parts(server, scene)
    return frames


def add_obstacle_parts(server: viser.ViserServer, scene: Scene) -> None:
    """Every obstacle's convex parts as meshes under its node /obstacles/<name> (a frame, or
    a drag gizmo in `live`).

    Args:
        server: the viser server to draw in.
        scene: the scene whose obstacles are drawn.
    """
    for obstacle in scene.obstacles:
        for i, part in enumerate(obstacle.parts):
            hull = trimesh.convex.convex_hull(part.vertices)
            server.scene.add_mesh_simple(
                f"/obstacles/{obstacle.name}/part_{i}",
                np.asarray(hull.vertices, np.float32),
                np.asarray(hull.faces, np.uint32),
                color=OBSTACLE_COLOUR,
                opacity=0.8,
            )


def pose_of(wxyz: np.ndarray, position: np.ndarray) -> np.ndarray:
    """The 4×4 pose of viser's (quaternion w, x, y, z; position).

    Args:
        wxyz: a quaternion (w, x, y, z), shape (4,) (normalised here).
        position: a position, shape (3,) [m].

    Returns:
        The homogeneous transform, shape (4, 4) [m].
    """
    w, x, y, z = np.asarray(wxyz, dtype=float)
    T = np.eye(4)
    T[:3, :3] = pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()
    T[:3, 3] = position
    return T


def add_path(server: viser.ViserServer, name: str, points: np.ndarray, colour: tuple) -> None:
    """A polyline through `points` as line segments (nothing for fewer than two points).

    Args:
        server: the viser server to draw in.
        name: the scene node's name, e.g. "/reference".
        points: the polyline's vertices, shape (n, 3) [m].
        colour: its colour (r, g, b), 0-255 each.
    """
    if len(points) < 2:
        return
    segments = np.stack([points[:-1], points[1:]], axis=1).astype(np.float32)
    server.scene.add_line_segments(name, segments, colour, thickness=3.0, thickness_units="screen")
