"""`articula live`: a scene's planner in real time in the browser, obstacles dragged by hand.

Every control period reads each obstacle's drag gizmo, steps the same OnlineController that
`articula plan` uses (its obstacles live), and hands the arm's picture to a painter thread
that moves it on the page (viewer/painter.py: the loop never waits on the browser). The
end-effector target follows the scene's trajectory (drawn in blue) or a goal marker of its own:
dragging the marker switches the following off, and the readout then gives the tool's error
from the goal. The method, Λ and d_min can be changed from the panel (the controller is
rebuilt from the arm's current configuration); the gizmos are sized to the arm. With a plant
(`--plant mujoco`, viewer/live_plant.py) the commands drive the MuJoCo twin, the controller
closes its loop on the joints it measures, and the measured arm is drawn beside the commanded
one; a checkbox each shows or hides them.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import viser

from articula.arms.pacing import Pacer
from articula.errors import ArticulaError
from articula.loops.online import OnlineController
from articula.planning.config import (
    METHODS,
    PlannerSpec,
)
from articula.robots.sweep import joint_sweep
from articula.signals import Terminated, terminate_as_interrupt
from articula.viewer import drawing
from articula.viewer.live_plant import COMMANDED_OPACITY, LivePlant
from articula.viewer.live_record import Recording
from articula.viewer.live_scene import LiveScene
from articula.viewer.painter import Painter
from articula.viewer.run_data import visuals_of

READOUT_EVERY = 9  # periods between readouts (~10 a second, what a person reads); a
# multiple of DRAW_EVERY, as a readout goes out with a picture
DRAW_EVERY = 3  # periods between pictures: 33 Hz at 10 ms, smooth to the eye (each is
# pushed to the page by the painter's thread, viewer/painter.py: the loop never waits on it)
OBSTACLE_GIZMO = 0.6  # an obstacle's drag gizmo, as a fraction of the arm's reach
GOAL_GIZMO = 0.5  # the goal marker's, likewise
REFERENCE_POINTS = 2000  # vertices of the drawn reference path


class Live:
    """The live page of one scene file in one viser server.

    Args:
        server: the viser server the page is served by.
        loaded: the scene file, read and checked.
    """

    def __init__(self, server: viser.ViserServer, loaded: LiveScene) -> None:
        self.server = server
        self.config = loaded.config
        self.scene, self.q0, self.targets = loaded.scene, loaded.q0, loaded.targets
        planner = self.config["planner"]
        gui = server.gui
        self.method = gui.add_dropdown(
            "method", METHODS, initial_value=planner.get("method", "baornn")
        )
        self.lam = gui.add_number("Λ", float(planner.get("lambda_weight", 0.0)), min=0.0, step=1e-4)
        self.d_min = gui.add_number(
            "d_min [m]", float(planner.get("d_min", 0.0)), min=0.0, step=1e-3
        )
        self.follow = gui.add_checkbox("follow the trajectory", True)
        self.show_commanded = gui.add_checkbox("commanded arm", True)
        self.readout = gui.add_markdown("")
        self.refusal: str | None = None  # the last refused setting, shown until a change
        self._reverting = False  # the panel is being put back: not a change of the user's
        for handle in (self.method, self.lam, self.d_min):
            handle.on_update(lambda _: None if self._reverting else self.rebuild())
        server.scene.add_grid("/grid", width=2.0, height=2.0, cell_size=0.1)
        drawing.aim_camera(server)
        visuals = visuals_of(self.config["robot"], self.scene)
        ghost = None if loaded.validated.plant is None else COMMANDED_OPACITY
        self.frames, self.meshes = drawing.add_robot(server, visuals, opacity=ghost)
        self.show_commanded.on_update(lambda _: self._show_arm(self.frames, self.show_commanded))
        reach = float(joint_sweep(self.scene.robot)[0])  # [m] the arm's size sets the gizmos'
        self.gizmos = {}
        for obstacle in self.scene.obstacles:
            wxyz, position = drawing.wxyz_position(obstacle.pose_at(0.0))
            self.gizmos[obstacle.name] = server.scene.add_transform_controls(
                f"/obstacles/{obstacle.name}", OBSTACLE_GIZMO * reach, wxyz=wxyz, position=position
            )
        drawing.add_obstacle_parts(server, self.scene)
        horizon = self.targets.duration + float(planner.get("duration", 50.0))
        path = [self.targets(t).position for t in np.linspace(0.0, horizon, REFERENCE_POINTS)]
        drawing.add_path(server, "/reference", np.array(path), drawing.REFERENCE_COLOUR)
        self.target = server.scene.add_transform_controls(
            "/target", GOAL_GIZMO * reach, disable_rotations=True
        )
        self.target.on_update(self._goal_moved)
        server.scene.add_icosphere("/target/ball", radius=0.01, color=drawing.REFERENCE_COLOUR)
        self.recording = Recording()
        self.colours: dict[str, tuple[int, int, int]] = {}  # as painted (painter's thread)
        self.painter = Painter(server)
        self.periods = 0
        self.controller: OnlineController | None = None
        self.q = self.q0.copy()
        self.plant = None
        if loaded.validated.plant is not None:
            self.plant = LivePlant(server, loaded.validated, self.scene, self.q0, visuals)
            self.show_measured = gui.add_checkbox("measured arm", True)
            self.show_measured.on_update(
                lambda _: self._show_arm(self.plant.frames, self.show_measured)
            )
        self.rebuild()

    @property
    def dt(self) -> float:
        """The control period [s]."""
        return float(self.config["planner"].get("dt", 0.01))

    def spec(self) -> PlannerSpec:
        """The planner of the scene file with the panel's method, Λ and d_min.

        Returns:
            The planner's settings.
        """
        panel = {
            "method": self.method.value,
            "lambda_weight": float(self.lam.value),
            "d_min": float(self.d_min.value),
        }
        return PlannerSpec(**(self.config["planner"] | panel))

    def rebuild(self) -> None:
        """A new controller from the panel's settings, started from the arm where it is and
        as it moves (its acceleration limit holds across the change); on a start it refuses
        (within the new d_min, say) the old one goes on, the panel is put back to the
        settings in force, and the refusal stays in the readout until the next change."""
        try:
            spec = self.spec()
            seed = int(spec.seed or 0)
            controller = OnlineController.from_spec(self.scene, spec, seed, live_obstacles=True)
            self._push_poses(controller)
            q = self.recording.q
            velocity = None
            if len(q) >= 2:
                velocity = self.scene.robot.difference(q[-1], q[-2]) / self.dt
            controller.reset(self.q, velocity)
        except ArticulaError as exc:
            if self.controller is None:
                raise  # the scene file's own settings do not start: nothing to show
            self.refusal = f"**not changed:** {exc}"
            self._revert_panel()
            self.readout.content = self.refusal
            return
        self.refusal = None
        self.controller = controller
        self.config["planner"] |= {
            "method": spec.method,
            "lambda_weight": spec.lambda_weight,
            "d_min": spec.d_min,
        }

    def _goal_moved(self, event: viser.TransformControlsEvent) -> None:
        """A drag of the goal marker begins: the following switches off (the goal stays where
        the marker is let go, until the box is ticked again)."""
        if event.phase == "start":
            self.follow.value = False

    @staticmethod
    def _show_arm(frames: dict[str, viser.FrameHandle], box: viser.GuiCheckboxHandle) -> None:
        """Show or hide an arm's link frames (and so its meshes) as its checkbox says."""
        for frame in frames.values():
            frame.visible = box.value

    def _revert_panel(self) -> None:
        """Put the panel's method, Λ and d_min back to the controller's in force."""
        planner = self.config["planner"]
        self._reverting = True
        try:
            self.method.value = planner.get("method", "baornn")
            self.lam.value = float(planner.get("lambda_weight", 0.0))
            self.d_min.value = float(planner.get("d_min", 0.0))
        finally:
            self._reverting = False

    def period(self) -> float:
        """One control period: obstacles from their gizmos, one planner step, the page
        updated.

        Returns:
            The wall time the planner's step took [s].
        """
        controller = self.controller
        assert controller is not None
        t = self.periods * self.dt
        if self.follow.value:
            target = self.targets(t).position
        else:
            target = np.asarray(self.target.position, dtype=float)
        poses = self._gizmo_poses()
        measured = None if self.plant is None else self.plant.q
        start = time.perf_counter()
        self.q = controller.step(target, poses, q_measured=measured)
        elapsed = time.perf_counter() - start
        if self.plant is not None:
            self.plant(self.q, poses)
            self.recording.measured_clearance.append(self.plant.clearance())
        self.periods += 1
        self.recording.step_ms.append(1e3 * elapsed)
        self._show(t, target, poses, elapsed)
        return elapsed

    def _show(
        self, t: float, target: np.ndarray, poses: dict[str, np.ndarray], elapsed: float
    ) -> None:
        """Record the period (its self clearance too when the scene checks link pairs), and
        update the page every DRAW_EVERY periods (at once when the planner ran over)."""
        scene = self.controller.planner.scene  # its obstacles are the live ones
        x = scene.robot.ee_position(self.q)
        late = elapsed > self.dt
        if late or self.periods % DRAW_EVERY == 0:
            d = (
                scene.distances(self.q, t)
                if scene.obstacles
                else np.full((len(scene.robot.links), 1), np.inf)
            )
            clearance = float(d.min())
            self_clearance = float(np.min(scene.self_distances(self.q), initial=np.inf))
            self._draw(d, x, target, clearance, elapsed)
        else:
            clearance, self_clearance = scene.clearances(self.q, t)
        checked = self_clearance if scene.self_pairs else None
        self.recording.add(t, self.q, x, target, clearance, poses, checked)

    def _draw(
        self, d: np.ndarray, x: np.ndarray, target: np.ndarray, clearance: float, elapsed: float
    ) -> None:
        """Hand the painter the arm's link poses, its links' colours by clearance (d: links ×
        obstacles [m]) and the readout (every READOUT_EVERY periods, or when over the
        period)."""
        scene = self.controller.planner.scene
        late = elapsed > self.dt
        poses = scene.robot.link_poses(self.q)
        moves = [
            (f, *drawing.wxyz_position(poses[n])) for n, f in self.frames.items() if n in poses
        ]
        d_min = float(self.d_min.value)
        colours = {
            link.name: drawing.clearance_colour(float(d[i].min()), d_min)
            for i, link in enumerate(scene.robot.links)
        }
        if self.plant is not None:
            moves += self.plant.link_moves()
        readout = None
        if late or self.periods % READOUT_EVERY == 0:
            readout = self._readout(x, target, clearance, elapsed)
        shown = target.copy() if self.follow.value else None
        self.painter.post(lambda: self._paint(moves, colours, readout, shown))

    def _readout(self, x: np.ndarray, target: np.ndarray, clearance: float, elapsed: float) -> str:
        """The panel's line: clearance, error, the planner's time (and the measured arm's)."""
        error = float(np.linalg.norm(x - target))
        name = "error" if self.follow.value else "goal error"  # the marker's goal, not the path
        readout = f"clearance **{1e3 * clearance:.1f} mm** · {name} {1e3 * error:.2f} mm"
        if self.plant is not None:
            tool = self.scene.robot.ee_position(self.plant.q)
            readout += (
                f" · measured: error {1e3 * float(np.linalg.norm(tool - target)):.2f} mm,"
                f" clearance {1e3 * self.recording.measured_clearance[-1]:.1f} mm,"
                f" contacts {self.plant.arm.contacts[-1]}"
            )
        readout += f" · planner {1e3 * elapsed:.2f} ms per {1e3 * self.dt:.0f} ms period"
        readout += " · **over the period**" if elapsed > self.dt else ""
        return readout if self.refusal is None else f"{self.refusal}  \n{readout}"

    def _paint(
        self,
        moves: list[tuple[viser.FrameHandle, np.ndarray, np.ndarray]],
        colours: dict[str, tuple[int, int, int]],
        readout: str | None,
        target: np.ndarray | None,
    ) -> None:
        """On the painter's thread: move the arm's link frames (moves: frame, wxyz, position),
        and the target it follows, recolour the links whose colour changed since the last
        picture, write the readout."""
        if target is not None:
            self.target.position = target
        for frame, wxyz, position in moves:
            frame.wxyz, frame.position = wxyz, position
        for name, colour in colours.items():
            if self.colours.get(name) != colour:  # only what changed goes out
                self.colours[name] = colour
                for mesh in self.meshes.get(name, ()):
                    mesh.color = colour
        if readout is not None:
            self.readout.content = readout

    def close(self) -> None:
        """Stop the painter (after its last picture)."""
        self.painter.stop()

    def _gizmo_poses(self) -> dict[str, np.ndarray]:
        """Every obstacle's pose (4×4, world) from its gizmo."""
        return {name: drawing.pose_of(g.wxyz, g.position) for name, g in self.gizmos.items()}

    def _push_poses(self, controller: OnlineController) -> None:
        """Give a new controller the obstacles where the gizmos hold them now."""
        for name, T in self._gizmo_poses().items():
            controller.live[name].pose = T

    def write(self, folder: Path, wall_time: float) -> dict[str, Any]:
        """The recording as a run folder `articula view` replays.

        Args:
            folder: the run folder to write.
            wall_time: the session's wall-clock duration, for the record [s].

        Returns:
            The run's record (record.json).
        """
        iterations = float(self.controller.planner.iterations) if self.controller else 0.0
        plant = None if self.plant is None else self.plant.arm
        return self.recording.write(
            folder, self.config, self.scene, self.q0, self.dt, iterations, plant, wall_time
        )


def run_live(
    scene_file: Path,
    method: str | None,
    host: str,
    port: int,
    record: Path | None,
    announce,
    plant: str | None = None,
) -> None:
    """Serve the live page until Ctrl-C or SIGTERM, a period every dt; then write --record if
    asked, and the interrupt goes on (the CLI exits 130 or 143).

    Args:
        scene_file: the scene TOML to run (with [planner] and [trajectory]).
        method: the planner method to start with; None: the scene file's.
        host: the address to listen on.
        port: the TCP port to listen on.
        record: the run folder to write the session to at the end; None: none.
        announce: called as announce(url) once the page is served.
        plant: "mujoco" or "none" instead of the file's [plant]; None: the file's.
    """
    from articula.viewer.replay import open_server, stop_server

    loaded = LiveScene.load(scene_file, method, plant)  # a bad file fails before the port opens
    server = open_server(host, port)
    started = time.monotonic()
    live, interrupted = None, False
    with terminate_as_interrupt():
        try:
            live = Live(server, loaded)
            live.period()  # the loop runs before the URL goes out: a record is never empty
            announce(f"http://{host}:{port}")
            pacer = Pacer(live.dt, catch_up=False)  # late: the next period starts now
            pacer.wait()  # the first release: the period above was it
            while True:
                pacer.wait()
                live.period()
        except (KeyboardInterrupt, Terminated):  # Ctrl-C or SIGTERM: the session is written
            interrupted = True
            raise
        finally:
            if live is not None:
                live.close()
            stop_server(server)
            if interrupted and record is not None and live is not None:
                live.write(record, time.monotonic() - started)
