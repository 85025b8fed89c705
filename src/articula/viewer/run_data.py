"""A planner's run folder read for display: its scene, trace, and what each link looks like."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import trimesh
from scipy.spatial.transform import Rotation

from articula.errors import ArticulaError, ConfigError
from articula.experiments.plan import NAME as PLAN
from articula.experiments.plan import build_plan
from articula.robots.model import BUILTIN
from articula.robots.urdf_visuals import Visual, visual_meshes
from articula.runs.folders import CONFIG, RECORD, TRACE
from articula.runs.records import read_record
from articula.scene.obstacles import Obstacle
from articula.scene.scene import Scene

TRACK = ("x", "y", "z", "qw", "qx", "qy", "qz")  # a live run's obstacle pose columns


@dataclass(frozen=True)
class Closest:
    """The closest link-obstacle pair at one time: names, witness points [m, world] and the
    signed distance [m].

    Attributes:
        link: the link's name.
        obstacle: the obstacle's name.
        on_link: the link's closest point, world frame, shape (3,) [m].
        on_obstacle: the obstacle's closest point, world frame, shape (3,) [m].
        distance: their signed distance (negative: penetrating) [m].
    """

    link: str
    obstacle: str
    on_link: np.ndarray
    on_obstacle: np.ndarray
    distance: float


@dataclass
class RunData:
    """What `articula view` shows of one run: the scene rebuilt from its config.toml, the
    trace's time series (t [s], q [rad], x and x_ref [m], error and clearance [m]) and the
    links' meshes (visual where the URDF has them, else the collision hulls).

    Attributes:
        folder: the run folder.
        scene: the robot and obstacles, rebuilt from config.toml.
        t: sample times, shape (N,) [s].
        q: joint positions, shape (N, nq) [rad].
        x: achieved end-effector positions, shape (N, 3) [m].
        x_ref: reference end-effector positions, shape (N, 3) [m].
        error: tracking error |x - x_ref|, shape (N,) [m].
        clearance: smallest link-obstacle clearance, shape (N,) [m] (inf without any).
        visuals: link name -> its meshes and their poses in the link frame.
        d_min: the planner's safety distance [m] (0 when the config gives none).
        obstacle_track: obstacle name -> its recorded pose per sample, shape (N, 7): x, y, z
            [m], qw, qx, qy, qz (a live run's dragged obstacles; empty otherwise).
    """

    folder: Path
    scene: Scene
    t: np.ndarray
    q: np.ndarray
    x: np.ndarray
    x_ref: np.ndarray
    error: np.ndarray
    clearance: np.ndarray
    visuals: dict[str, list[Visual]]
    d_min: float
    obstacle_track: dict[str, np.ndarray]

    def link_poses(self, k: int) -> dict[str, np.ndarray]:
        """Pose (4×4, world) of every link with something to draw, at sample k.

        Args:
            k: the sample's index.

        Returns:
            Link name -> its pose, shape (4, 4) [m].
        """
        poses = self.scene.robot.link_poses(self.q[k])
        return {name: poses[name] for name in self.visuals if name in poses}

    def obstacle_poses(self, k: int) -> dict[str, np.ndarray]:
        """Pose (4×4, world) of every obstacle at sample k: the recorded one of a live run,
        else the scene's.

        Args:
            k: the sample's index.

        Returns:
            Obstacle name -> its pose, shape (4, 4) [m].
        """
        return {
            o.name: self._track(o.name, k)
            if o.name in self.obstacle_track
            else o.pose_at(float(self.t[k]))
            for o in self.scene.obstacles
        }

    def _track(self, name: str, k: int) -> np.ndarray:
        """The recorded pose of obstacle `name` at sample k."""
        row = self.obstacle_track[name][k]
        x, y, z, w = row[4], row[5], row[6], row[3]
        T = np.eye(4)
        T[:3, :3] = Rotation.from_quat([x, y, z, w]).as_matrix()
        T[:3, 3] = row[:3]
        return T

    def link_clearances(self, k: int) -> dict[str, float]:
        """Each link's smallest distance to any obstacle at sample k (+inf without any).

        Args:
            k: the sample's index.

        Returns:
            Link name -> its signed clearance [m].
        """
        if not self.scene.obstacles:
            return {link.name: np.inf for link in self.scene.robot.links}
        d = self._scene_at(k).distances(self.q[k], float(self.t[k]))
        return {link.name: float(d[i].min()) for i, link in enumerate(self.scene.robot.links)}

    def closest(self, k: int) -> Closest | None:
        """The closest link-obstacle pair at sample k, None without obstacles.

        Args:
            k: the sample's index.

        Returns:
            The pair with its witness points and distance; None when the scene has no obstacle.
        """
        if not self.scene.obstacles:
            return None
        w = self._scene_at(k).witnesses(self.q[k], float(self.t[k]))
        li, oi = np.unravel_index(int(np.argmin(w.distance)), w.distance.shape)
        return Closest(
            self.scene.robot.links[li].name,
            self.scene.obstacles[oi].name,
            w.on_link[li, oi].copy(),
            w.on_obstacle[li, oi].copy(),
            float(w.distance[li, oi]),
        )

    def _scene_at(self, k: int) -> Scene:
        """The scene with its obstacles where they were at sample k."""
        if not self.obstacle_track:
            return self.scene
        poses = self.obstacle_poses(k)
        obstacles = [Obstacle(o.name, o.parts, poses[o.name]) for o in self.scene.obstacles]
        return Scene(
            self.scene.robot,
            obstacles,
            self.scene.broadphase,
            self.scene.metric,
            self.scene.self_pair_names,
            self.scene.self_d_min,
        )


class RunFolderError(ConfigError):
    """A folder `view` cannot show (no trace, not a planner's run)."""


def run_folders(folder: Path) -> list[Path]:
    """The planner runs in `folder`: itself when it is one, else a sweep's run folders that are
    (sorted); RunFolderError when there is none.

    Args:
        folder: a run folder, or a sweep's folder of them.

    Returns:
        The run folders to show, at least one.
    """
    if not folder.is_dir():
        raise RunFolderError("RUN_DIR", f"{folder} is not a folder")
    if (folder / CONFIG).is_file() or (folder / TRACE).is_file():
        return [folder]
    runs = sorted(p for p in folder.iterdir() if p.is_dir() and _is_plan(p))
    if not runs:
        raise RunFolderError(
            "RUN_DIR",
            f"{folder} holds no planner run (a folder with config.toml and "
            "trace.parquet written by `articula plan`, or a sweep of them)",
        )
    return runs


def _is_plan(folder: Path) -> bool:
    """Whether `folder` is a planner's run folder."""
    try:
        config = tomllib.loads((folder / CONFIG).read_text())
    except (OSError, ValueError):
        return False
    return config.get("experiment") == PLAN and (folder / TRACE).is_file()


def load_run(folder: Path) -> RunData:
    """The run in `folder`; RunFolderError naming what is missing.

    Args:
        folder: a planner's run folder (config.toml and trace.parquet).

    Returns:
        The run's scene, time series and link meshes.
    """
    try:
        config = tomllib.loads((folder / CONFIG).read_text())
    except FileNotFoundError:
        raise RunFolderError("RUN_DIR", f"{folder} has no {CONFIG}: not a run folder") from None
    except (OSError, ValueError) as exc:
        raise RunFolderError("RUN_DIR", f"cannot read {folder / CONFIG} ({exc})") from None
    if config.get("experiment") != PLAN:
        raise RunFolderError(
            "RUN_DIR",
            f"{folder} is a run of {config.get('experiment')!r}; view shows {PLAN} "
            "runs (articula plan)",
        )
    try:
        trace = pq.read_table(folder / TRACE).to_pydict()
    except (OSError, ValueError) as exc:
        raise RunFolderError("RUN_DIR", f"{folder} has no readable {TRACE} ({exc})") from None
    try:  # written last: without it the run did not finish (or its folder was damaged)
        read_record(folder)
    except (OSError, ValueError) as exc:
        raise RunFolderError(
            "RUN_DIR",
            f"{folder / RECORD} is missing or unreadable ({type(exc).__name__}): the run did not "
            "finish; plan it again",
        ) from None
    scene = build_plan(config, folder, str(folder / CONFIG)).scene  # errors named as `plan`
    nq = scene.robot.nq
    column = lambda *names: np.column_stack([trace[n] for n in names])  # noqa: E731
    return RunData(
        folder=folder,
        scene=scene,
        t=np.asarray(trace["t"]),
        q=column(*(f"q_{i + 1}" for i in range(nq))),
        x=column("x", "y", "z"),
        x_ref=column("x_ref", "y_ref", "z_ref"),
        error=np.asarray(trace["error"]),
        clearance=np.asarray(trace["clearance"]),
        visuals=visuals_of(config["robot"], scene),
        d_min=float(config.get("planner", {}).get("d_min", 0.0)),
        obstacle_track={
            o.name: column(*(f"obstacle_{o.name}_{c}" for c in TRACK))
            for o in scene.obstacles
            if f"obstacle_{o.name}_x" in trace
        },
    )


def visuals_of(robot: dict, scene: Scene) -> dict[str, list[Visual]]:
    """The URDF's visual meshes of the scene's links, or their collision hulls when the URDF
    has none or they cannot be read.

    Args:
        robot: the config's [robot] table (builtin, or urdf and package_dirs).
        scene: the scene built from that config.

    Returns:
        Link name -> its meshes and their poses in the link frame.
    """
    if "builtin" in robot:
        relative = BUILTIN[robot["builtin"]][0]
        urdf = Path(str(resources.files("articula.robots") / "data" / relative))
    else:
        urdf = Path(robot["urdf"])
    try:
        visuals = visual_meshes(urdf, [Path(d) for d in robot.get("package_dirs", [])])
    except ArticulaError:
        visuals = {}
    model = scene.robot.model
    drawn = {name: v for name, v in visuals.items() if model.existFrame(name) and v}
    if drawn:
        return drawn
    return {
        link.name: [
            Visual(trimesh.convex.convex_hull(shape.vertices), T, None)
            for shape, T in zip(link.shapes, link.placements, strict=True)
        ]
        for link in scene.robot.links
    }
