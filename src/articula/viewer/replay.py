"""`articula view`: a planner's run replayed in the browser (viser).

The page shows the links (their URDF visual meshes, else collision hulls) coloured by
clearance, the obstacles, the reference path (blue) and the achieved end-effector path
(green), and at the current time the closest link-obstacle pair as a red segment between its
witness points with its distance. The panel has a run picker (a sweep folder), a time slider,
play/pause and speed, a trail (the arm at TRAIL_POSES times over the run, as MoveIt's
trajectory trail), and plots of error and clearance against time with a cursor at the
scene's time (viewer/time_plot.py).
"""

from __future__ import annotations

import errno
import socket
import time
from pathlib import Path

import numpy as np
import viser

from articula.errors import ConfigError
from articula.native import captured_output
from articula.signals import terminate_as_interrupt
from articula.viewer import drawing
from articula.viewer.run_data import RunData, load_run, run_folders
from articula.viewer.time_plot import TimePlot

SPEEDS = ("0.25", "0.5", "1", "2", "4")
FRAME_S = 1.0 / 30.0  # [s] between frames while playing
ERROR_FLOOR_MM = 1e-3  # [mm] the error plot's floor on its log axis (1 µm)
TRAIL_POSES = 8  # arms drawn along the run by the trail
TRAIL_OPACITY = 0.25


class Replay:
    """The replay of the runs in a folder, in one viser server (every browser tab sees the same
    state).

    Args:
        server: the viser server the page is served by.
        runs: the run folders to pick from, at least one (the first is shown).
    """

    def __init__(self, server: viser.ViserServer, runs: list[Path]) -> None:
        self.server = server
        self.runs = {path.name: path for path in runs}
        gui = server.gui
        self.picker = gui.add_dropdown(
            "run", tuple(self.runs), initial_value=runs[0].name, visible=len(runs) > 1
        )
        self.slider = gui.add_slider("time [s]", 0.0, 1.0, 0.01, 0.0)
        self.playing = gui.add_checkbox("play", False)
        self.speed = gui.add_dropdown("speed", SPEEDS, initial_value="1")
        self.trail = gui.add_checkbox("trail", False)
        self.status = gui.add_markdown("")
        self.plots: list[TimePlot] = []
        self.ghosts: list[viser.FrameHandle] = []
        self.run: RunData | None = None
        self.index = 0
        self.picker.on_update(lambda _: self.load(self.runs[self.picker.value]))
        self.slider.on_update(lambda _: self._time_set())
        self.trail.on_update(lambda _: self._draw_trail())
        drawing.aim_camera(server)
        self.load(runs[0])

    def load(self, folder: Path) -> None:
        """Show the run in `folder` from its start.

        Args:
            folder: a planner's run folder.
        """
        run = load_run(folder)
        self.run = run
        scene = self.server.scene
        scene.reset()
        scene.add_grid("/grid", width=2.0, height=2.0, cell_size=0.1)
        self.frames, self.meshes = drawing.add_robot(self.server, run.visuals)
        self.obstacles = drawing.add_obstacles(self.server, run.scene, float(run.t[0]))
        drawing.add_path(self.server, "/reference", run.x_ref, drawing.REFERENCE_COLOUR)
        drawing.add_path(self.server, "/achieved", run.x, drawing.PATH_COLOUR)
        self.closest_line = None
        self.closest_label = None
        self.slider.max = float(run.t[-1])
        self.slider.step = float(run.t[1] - run.t[0]) if len(run.t) > 1 else 0.01
        for plot in self.plots:
            plot.remove()
        gui = self.server.gui
        error = np.maximum(1e3 * run.error, ERROR_FLOOR_MM)
        clearance = 1e3 * np.where(np.isfinite(run.clearance), run.clearance, np.nan)
        self.plots = [
            # Log axis: the approach's 100 mm and the path's tenths of a millimetre both show
            # (floored at 1 µm, where a log axis would lose an exact zero).
            TimePlot(gui, "error [mm], log", run.t, error, log=True),
            TimePlot(gui, "clearance [mm]", run.t, clearance),
        ]
        self.ghosts = []  # the scene's reset took them
        self._draw_trail()
        self.show(0)

    def show(self, k: int) -> None:
        """Put the arm, the obstacles and the closest pair at sample k.

        Args:
            k: the sample's index.
        """
        run = self.run
        assert run is not None
        self.index = k
        for name, T in run.link_poses(k).items():
            wxyz, position = drawing.wxyz_position(T)
            self.frames[name].wxyz, self.frames[name].position = wxyz, position
        for name, T in run.obstacle_poses(k).items():
            wxyz, position = drawing.wxyz_position(T)
            self.obstacles[name].wxyz, self.obstacles[name].position = wxyz, position
        for name, d in run.link_clearances(k).items():
            for mesh in self.meshes.get(name, ()):
                mesh.color = drawing.clearance_colour(d, run.d_min)
        closest = run.closest(k)
        text = f"t = {run.t[k]:.2f} s · error {1e3 * run.error[k]:.2f} mm"
        if closest is not None:
            points = np.array([[closest.on_link, closest.on_obstacle]], dtype=np.float32)
            self.closest_line = self.server.scene.add_line_segments(
                "/closest", points, drawing.CLOSEST_COLOUR, thickness=4.0, thickness_units="screen"
            )
            self.closest_label = self.server.scene.add_label(
                "/closest/label",
                f"{1e3 * closest.distance:.1f} mm",
                position=(closest.on_link + closest.on_obstacle) / 2,
            )
            text += (
                f" · closest: {closest.link} – {closest.obstacle}, {1e3 * closest.distance:.1f} mm"
            )
        self.status.content = text
        for plot in self.plots:
            plot.at(float(run.t[k]))

    def _draw_trail(self) -> None:
        """Draw the arm see-through at TRAIL_POSES evenly spaced samples (trail ticked), or take
        those arms away."""
        for frame in self.ghosts:
            frame.remove()
        self.ghosts = []
        run = self.run
        if run is None or not self.trail.value:
            return
        for i, k in enumerate(np.linspace(0, len(run.t) - 1, TRAIL_POSES).astype(int)):
            frames, _ = drawing.add_robot(
                self.server, run.visuals, f"/trail/{i}", opacity=TRAIL_OPACITY
            )
            for name, T in run.link_poses(int(k)).items():
                frames[name].wxyz, frames[name].position = drawing.wxyz_position(T)
            self.ghosts += frames.values()

    def tick(self, elapsed: float) -> None:
        """Advance by `elapsed` of wall time times the speed while playing.

        Args:
            elapsed: wall time since the last tick [s].
        """
        run = self.run
        if run is None or not self.playing.value:
            return
        t = float(run.t[self.index]) + elapsed * float(self.speed.value)
        if t > run.t[-1]:
            t = float(run.t[0])  # loop
        self.slider.value = t
        self.show(self._index_at(t))

    def _time_set(self) -> None:
        """Show the sample at the slider's time. viser hands on a time typed into its box as
        it is, beyond the run too, and the box would keep it: such a time is put back within
        the run (this is called again with it), so the box shows the time drawn."""
        t = float(np.clip(self.slider.value, self.slider.min, self.slider.max))
        if t != self.slider.value:
            self.slider.value = t
            return
        self.show(self._index_at(t))

    def _index_at(self, t: float) -> int:
        """The sample at time t [s] (the last one at or before it)."""
        assert self.run is not None
        return int(np.clip(np.searchsorted(self.run.t, t + 1e-9) - 1, 0, len(self.run.t) - 1))


def open_server(host: str, port: int) -> viser.ViserServer:
    """A viser server on host:port; ConfigError naming --port when it is taken, --host when
    the address is not this machine's.

    Args:
        host: the address to listen on.
        port: the TCP port to listen on.

    Returns:
        The running server.
    """
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError as exc:
            if exc.errno in (errno.EADDRINUSE, errno.EACCES):  # the port: taken or privileged
                raise ConfigError(
                    "--port", f"cannot listen on {host}:{port} ({exc.strerror}); choose another"
                ) from None
            raise ConfigError(  # not a name or address of this machine
                "--host",
                f"cannot listen on {host} ({exc.strerror or exc}); give an address of this "
                "machine, e.g. 127.0.0.1 or 0.0.0.0",
            ) from None
    with captured_output():  # viser's banner: the command prints its own one line
        return viser.ViserServer(host=host, port=port, verbose=False)


def stop_server(server: viser.ViserServer) -> None:
    """Stop a server of open_server without viser's "Server stopped" line.

    Args:
        server: the running server.
    """
    with captured_output():
        server.stop()


def serve(folder: Path, host: str, port: int, announce) -> None:
    """Serve the replay of `folder` until Ctrl-C or SIGTERM (KeyboardInterrupt or
    signals.Terminated goes on once the server is stopped); announce(url) once it listens.

    Args:
        folder: a planner's run folder, or a sweep's folder of them.
        host: the address to listen on.
        port: the TCP port to listen on.
        announce: called as announce(url) once the server listens.
    """
    runs = run_folders(folder)
    load_run(runs[0])  # a bad run fails before the server starts
    server = open_server(host, port)
    with terminate_as_interrupt():
        try:
            replay = Replay(server, runs)
            announce(f"http://{host}:{port}")
            last = time.monotonic()
            while True:
                time.sleep(FRAME_S)
                now = time.monotonic()
                replay.tick(now - last)
                last = now
        finally:
            stop_server(server)
