"""The dashboard server (port 29999): one command a line, one answer a line, as far as
ur-rtde's connect path and a stop need (PolyScope 5's wording)."""

from __future__ import annotations

import socket

from articula.arms.ur_fake.controller import PLAYING, Controller
from articula.arms.ur_fake.rtde_session import CONTROLLER_VERSION

__all__ = ["SERIAL_NUMBER", "serve_dashboard"]

SERIAL_NUMBER = "20215500001"
VERSION = ".".join(map(str, CONTROLLER_VERSION))


def serve_dashboard(conn: socket.socket, controller: Controller) -> None:
    """Answer one dashboard client until it quits or hangs up.

    Args:
        conn: the accepted socket.
        controller: the controller the commands act on.
    """
    with conn, conn.makefile("rwb", buffering=0) as stream:
        stream.write(b"Connected: Universal Robots Dashboard Server\n")
        for raw in stream:
            command = raw.decode("ascii", "replace").strip()
            with controller.lock:
                answer = _answer(command, controller)
            stream.write(answer.encode() + b"\n")
            if command == "quit":
                return


def _answer(command: str, c: Controller) -> str:
    """The dashboard's reply to one command (the caller holds the controller's lock)."""
    running = c.runtime_state == PLAYING
    if command == "PolyscopeVersion":
        return f"URSoftware {VERSION} (Mar 22 2021)"
    if command == "get serial number":
        return SERIAL_NUMBER
    if command == "is in remote control":
        return "true"
    if command == "stop":
        c.stop_program("the dashboard's stop")
        return "Stopped"
    if command == "running":
        return f"Program running: {str(running).lower()}"
    if command == "programState":
        name = c.program.name if c.program is not None else "<unnamed>"
        return f"{'PLAYING' if running else 'STOPPED'} {name}"
    if command == "robotmode":
        return "Robotmode: RUNNING"
    if command in ("safetymode", "safetystatus"):
        word = "PROTECTIVE_STOP" if c.protective else "NORMAL"
        return f"{command.capitalize()}: {word}"
    if command == "unlock protective stop":
        c.unlock_protective_stop()
        return "Protective stop releasing"
    if command == "quit":
        return "Disconnected"
    return f"could not understand: '{command}'"
