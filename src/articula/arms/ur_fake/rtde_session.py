"""One RTDE client connection (port 30004), protocol version 2: request protocol version,
get controller version, output and input recipe setup, start / pause, data packages both
ways. Each packet is a big-endian header (uint16 size with the header, uint8 type) and a body.
"""

from __future__ import annotations

import contextlib
import socket
import struct
import threading

from articula.arms.ur_fake.controller import Controller
from articula.arms.ur_fake.rtde_types import INPUTS, OUTPUTS, Recipe

__all__ = ["CONTROLLER_VERSION", "RtdeSession"]

CONTROLLER_VERSION = (5, 11, 0, 108249)  # major, minor, bugfix, build: an e-Series
PROTOCOL = 2
(REQUEST_PROTOCOL_VERSION, GET_URCONTROL_VERSION, TEXT_MESSAGE, DATA_PACKAGE,
 SETUP_OUTPUTS, SETUP_INPUTS, START, PAUSE) = (86, 118, 77, 85, 79, 73, 83, 80)  # fmt: skip
_HEADER = struct.Struct(">HB")


class RtdeSession:
    """The controller's side of one RTDE connection.

    Args:
        conn: the accepted socket.
        controller: the controller whose registers the inputs write.
        owners: input variable name -> the session that holds it (shared by all sessions:
            a register another client holds is IN_USE).

    Attributes:
        started: the client started synchronisation: outputs go out.
    """

    def __init__(
        self, conn: socket.socket, controller: Controller, owners: dict[str, RtdeSession]
    ) -> None:
        self._conn, self._controller, self._owners = conn, controller, owners
        self._send_lock = threading.Lock()
        self._output: Recipe | None = None
        self._every = 1  # controller cycles per output package
        self._inputs: dict[int, Recipe] = {}
        self.started = False
        self.closed = threading.Event()

    def serve(self) -> None:
        """Answer the client until it hangs up (on this connection's thread)."""
        try:
            while True:
                header = self._read(_HEADER.size)
                size, kind = _HEADER.unpack(header)
                self._handle(kind, self._read(size - _HEADER.size))
        except (ConnectionError, OSError):
            pass
        finally:
            self.close()

    def publish(self, cycle: int, values: dict[str, object]) -> None:
        """Send this cycle's output package, if synchronised and due.

        Args:
            cycle: the controller's cycle count.
            values: every output variable's value.
        """
        recipe = self._output
        if not self.started or recipe is None or cycle % self._every:
            return
        try:
            self._send(DATA_PACKAGE, recipe.pack(values))
        except OSError:  # the client is gone: its own thread cleans up (the caller holds the
            self.started = False  # controller's lock, which close() takes)
            with contextlib.suppress(OSError):
                self._conn.shutdown(socket.SHUT_RDWR)

    def close(self) -> None:
        """Hang up and release the input registers this client held."""
        self.started = False
        with self._controller.lock:
            for name in [n for n, owner in self._owners.items() if owner is self]:
                del self._owners[name]
        try:
            self._conn.close()
        finally:
            self.closed.set()

    def _handle(self, kind: int, body: bytes) -> None:
        if kind == REQUEST_PROTOCOL_VERSION:
            (version,) = struct.unpack(">H", body[:2])
            self._send(kind, bytes([version == PROTOCOL]))
        elif kind == GET_URCONTROL_VERSION:
            self._send(kind, struct.pack(">4I", *CONTROLLER_VERSION))
        elif kind == SETUP_OUTPUTS:
            (frequency,) = struct.unpack(">d", body[:8])
            names = _names(body[8:])
            types = [OUTPUTS.get(n, "NOT_FOUND") for n in names]
            ok = 0 < frequency <= 500 and "NOT_FOUND" not in types
            self._output = Recipe(1, names, types) if ok else None
            self._every = max(1, round(500 / frequency)) if ok else 1
            self._send(kind, bytes([1 if ok else 0]) + ",".join(types).encode())
        elif kind == SETUP_INPUTS:
            self._setup_inputs(_names(body))
        elif kind == START:
            self.started = self._output is not None
            self._send(kind, bytes([self.started]))
        elif kind == PAUSE:
            self.started = False
            self._send(kind, bytes([1]))
        elif kind == DATA_PACKAGE and body:
            recipe = self._inputs.get(body[0])
            if recipe is not None:
                values = recipe.unpack(body[1:])
                with self._controller.lock:
                    self._controller.write_inputs(values)

    def _setup_inputs(self, names: list[str]) -> None:
        with self._controller.lock:
            types = []
            for name in names:
                owner = self._owners.get(name, self)
                types.append("IN_USE" if owner is not self else INPUTS.get(name, "NOT_FOUND"))
            ok = all(t not in ("IN_USE", "NOT_FOUND") for t in types)
            recipe_id = 0
            if ok:
                recipe_id = len(self._inputs) + 1
                self._inputs[recipe_id] = Recipe(recipe_id, names, types)
                self._owners.update(dict.fromkeys(names, self))
        self._send(SETUP_INPUTS, bytes([recipe_id]) + ",".join(types).encode())

    def _send(self, kind: int, body: bytes) -> None:
        with self._send_lock:
            self._conn.sendall(_HEADER.pack(_HEADER.size + len(body), kind) + body)

    def _read(self, n: int) -> bytes:
        data = b""
        while len(data) < n:
            chunk = self._conn.recv(n - len(data))
            if not chunk:
                raise ConnectionError("the client hung up")
            data += chunk
        return data


def _names(body: bytes) -> list[str]:
    """A recipe's variable names, comma separated (ur-rtde ends them with a comma)."""
    return [n for n in body.decode("ascii", "replace").split(",") if n]
