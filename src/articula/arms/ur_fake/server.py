"""The fake UR controller on the network: the dashboard (29999), the primary and secondary
interfaces for programs (30001–30003) and RTDE (30004) on one address, the controller's 2 ms
cycle on a thread of its own, paced by the wall clock.

The ports are the ones a real controller has (ur-rtde does not let a client choose them), so
one fake takes one address; tests give each fake its own loopback address (127.0.0.2, ...).
"""

from __future__ import annotations

import contextlib
import socket
import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np

from articula.arms.pacing import Pacer
from articula.arms.ur_fake.controller import RATE, Controller, Event
from articula.arms.ur_fake.dashboard import serve_dashboard
from articula.arms.ur_fake.rtde_session import RtdeSession
from articula.arms.ur_fake.script_port import serve_script
from articula.errors import ConfigError
from articula.scene.scene import Scene
from articula.sim.twin import ServoGains

__all__ = ["DASHBOARD", "RTDE", "SCRIPT_PORTS", "FakeUR"]

DASHBOARD, RTDE, SCRIPT_PORTS = 29999, 30004, (30001, 30002, 30003)


class FakeUR:
    """A fake UR controller serving on `host`; a context manager (stops and joins on exit).

    Args:
        scene: the arm (six revolute joints) and its obstacles.
        q0: where the arm is at power-on, at rest, shape (6,) [rad].
        host: the address to listen on (its ports are the controller's).
        gains: the twin's joint servos.
        on_event: called with each controller Event (from the controller's thread).

    Attributes:
        controller: the controller (its state, events and log).
    """

    def __init__(
        self,
        scene: Scene,
        q0: np.ndarray,
        host: str = "127.0.0.1",
        gains: ServoGains | None = None,
        on_event: Callable[[Event], None] | None = None,
    ) -> None:
        if len(scene.robot.joint_names) != 6:
            raise ConfigError(
                "robot.urdf",
                f"a UR arm has 6 joints; this robot has {len(scene.robot.joint_names)}",
            )
        self.host = host
        self.controller = Controller(scene, q0, gains, on_event)
        self._owners: dict[str, RtdeSession] = {}
        self._sessions: list[RtdeSession] = []
        self._listeners: list[socket.socket] = []
        self._threads: list[threading.Thread] = []
        self._stop = threading.Event()

    def __enter__(self) -> FakeUR:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def start(self) -> None:
        """Listen on every port and start the controller's cycle."""
        serve = {DASHBOARD: serve_dashboard, RTDE: self._serve_rtde}
        serve |= dict.fromkeys(SCRIPT_PORTS, serve_script)
        try:
            for port, handler in serve.items():
                listener = socket.create_server((self.host, port), reuse_port=False)
                self._listeners.append(listener)
                self._spawn(self._accept, listener, handler)
        except OSError as exc:
            self.close()
            raise ConfigError(
                "--host",
                f"cannot listen on {self.host} port {port} ({exc.strerror}): another "
                "controller (or fake) has it; give another loopback address, 127.0.0.2 say",
            ) from None
        self._spawn(self._cycle)

    def close(self) -> None:
        """Stop the cycle, hang up on every client, stop listening."""
        self._stop.set()
        for listener in self._listeners:
            with contextlib.suppress(OSError):  # wakes its accept() (a close alone does not)
                listener.shutdown(socket.SHUT_RDWR)
            listener.close()
        for session in list(self._sessions):
            session.close()
        for thread in self._threads:
            if thread is not threading.current_thread():
                thread.join(timeout=5.0)

    def write_log(self, path: Path) -> None:
        """The controller's log of every cycle as a Parquet table: t [s], q_1..q_6 (measured
        [rad]), qc_1..qc_6 (commanded [rad]), runtime_state, contacts (MuJoCo's).

        Args:
            path: the file to write.
        """
        import pyarrow as pa

        from articula.runs.records import write_table

        with self.controller.lock:
            log = list(self.controller.log)
        t = np.array([row[0] for row in log])
        q, qc = np.array([row[1] for row in log]), np.array([row[2] for row in log])
        columns = {"t": t} | {f"q_{j + 1}": q[:, j] for j in range(6)}
        columns |= {f"qc_{j + 1}": qc[:, j] for j in range(6)}
        columns |= {"runtime_state": np.array([row[3] for row in log])}
        columns |= {"contacts": np.array([row[4] for row in log])}
        write_table(path, pa.table(columns))

    def _spawn(self, target: Callable[..., None], *args: object) -> None:
        thread = threading.Thread(target=target, args=args, daemon=True)
        self._threads.append(thread)
        thread.start()

    def _accept(self, listener: socket.socket, handler: Callable[..., None]) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = listener.accept()
            except OSError:
                return
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            threading.Thread(target=handler, args=(conn, self.controller), daemon=True).start()

    def _serve_rtde(self, conn: socket.socket, controller: Controller) -> None:
        session = RtdeSession(conn, controller, self._owners)
        self._sessions.append(session)
        try:
            session.serve()
        finally:
            self._sessions.remove(session)

    def _cycle(self) -> None:
        """The controller's 2 ms cycle, paced by the wall clock (late cycles catch up)."""
        pacer, cycle = Pacer(1.0 / RATE), 0
        while not self._stop.is_set():
            late = pacer.wait()
            with self.controller.lock:
                values = self.controller.tick(on_time=late < pacer.period)
                packages = list(self._sessions)
                for session in packages:
                    session.publish(cycle, values)
            cycle += 1
