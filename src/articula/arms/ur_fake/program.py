"""ur-rtde's control program (its rtde_control.script) as the fake runs it: one pass of the
script's main loop per controller cycle, reading the command from input_int_register 0 and
its arguments from the input registers, acknowledging in output_int_register 0 (1: ready for
a command, 2: done with it), at the register offset (0 or 24) the client injected.

Only the commands a servo stream uses are modelled: servoJ (11: q in double registers 0–5,
its time in 8, lookahead_time in 9, gain in 10), servoStop (16), stopL / stopJ (33, 34),
setWatchdog (35: the minimum frequency in double register 0), triggerProtectiveStop (31) and
stopScript (255). Any other command stops the program with a line saying it is not modelled,
as a real controller stops a program on a runtime error.
"""

from __future__ import annotations

import re
from typing import Protocol

__all__ = ["REALTIME", "ControlProgram", "Registers", "parse_program"]

REALTIME = {6, 9, 10, 11, 24, 25, 26, 27, 38, 58, 66, 67, 68, 69, 70, 71}  # no handshake
READY, DONE = 1, 2  # output_int_register 0: ready for a command, done with it
SERVOJ, SERVO_STOP, PROTECTIVE_STOP, STOPL, STOPJ, WATCHDOG, STOP_SCRIPT = (
    11,
    16,
    31,
    33,
    34,
    35,
    255,
)
_OFFSET = re.compile(r"global reg_offset_(int|float) = # (?:int|float) register offset\n(\d+)")


class Registers(Protocol):
    """What the program needs of the controller it runs on."""

    def input_int(self, index: int) -> int:
        """input_int_register_{index}.

        Args:
            index: the register's number (0–47).

        Returns:
            Its value.
        """
        ...

    def input_double(self, index: int) -> float:
        """input_double_register_{index}.

        Args:
            index: the register's number (0–47).

        Returns:
            Its value.
        """
        ...

    def set_output_int(self, index: int, value: int) -> None:
        """Write output_int_register_{index}.

        Args:
            index: the register's number (0–47).
            value: its new value.
        """
        ...

    def servoj(self, q: list[float], t: float, lookahead_time: float, gain: float) -> None:
        """Servo toward q; lookahead_time and gain are checked within servoj's ranges (a
        value outside stops the program, as a runtime error).

        Args:
            q: the target joints, six values [rad].
            t: the call's blocking time [s] (one cycle here).
            lookahead_time: servoj's smoothing time [s] (the follower's time constant).
            gain: servoj's proportional gain (checked, not used).
        """
        ...

    def brake(self, why: str) -> None:
        """Stop servoing and bring the arm to rest.

        Args:
            why: what asked for it, for the log.
        """
        ...

    def set_watchdog(self, register: str, frequency: float) -> None:
        """Stop the program when `register` is not written at least at `frequency`.

        Args:
            register: the watched input variable's name.
            frequency: the least rate it must be written at [Hz].
        """
        ...

    def protective_stop(self, why: str) -> None:
        """Brake, pause the program, flag the protective stop.

        Args:
            why: the cause, for the log.
        """
        ...


class NotModelledError(Exception):
    """The program asked for something the fake does not model."""


class ControlProgram:
    """ur-rtde's control script, one main-loop pass per cycle.

    Args:
        int_offset: the integer registers' offset (0, or 24 for the upper range).
        float_offset: the double registers' offset.
    """

    name = "rtde_control"

    def __init__(self, int_offset: int, float_offset: int) -> None:
        self.int_offset, self.float_offset = int_offset, float_offset
        self._executing = False

    def start(self, c: Registers) -> None:
        """The script's first lines: no async operation, ready for a command.

        Args:
            c: the controller.
        """
        c.set_output_int(self.int_offset + 2, -1)
        c.set_output_int(self.int_offset, READY)

    def cycle(self, c: Registers) -> bool:
        """One pass of the main loop (a `sync()` apart from the next).

        Args:
            c: the controller.

        Returns:
            Whether the program goes on (False after stopScript).

        Raises:
            NotModelledError: a command the fake does not model (the program stops on it).
        """
        cmd = c.input_int(self.int_offset)
        if cmd in REALTIME:
            going = self._process(cmd, c)
            c.set_output_int(self.int_offset, READY)
            return going
        if cmd == 0:
            self._executing = False
            c.set_output_int(self.int_offset, READY)
            return True
        going = True
        if not self._executing:
            going = self._process(cmd, c)
        self._executing = True
        return going

    def _process(self, cmd: int, c: Registers) -> bool:
        """One command, as the script's process_cmd; False for stopScript."""

        def d(i: int) -> float:
            return c.input_double(self.float_offset + i)

        if cmd == SERVOJ:
            c.servoj([d(i) for i in range(6)], d(8), d(9), d(10))
        elif cmd == SERVO_STOP:
            c.brake("servoStop")
        elif cmd in (STOPL, STOPJ):
            c.brake("stopL" if cmd == STOPL else "stopJ")
        elif cmd == WATCHDOG:
            c.set_watchdog(f"input_int_register_{self.int_offset}", d(0))
        elif cmd == PROTECTIVE_STOP:
            c.protective_stop("triggerProtectiveStop from the client")
        elif cmd == STOP_SCRIPT:
            return False
        else:
            raise NotModelledError(f"ur-rtde command {cmd} is not modelled by the fake controller")
        c.set_output_int(self.int_offset, DONE)
        return True


def parse_program(text: str) -> ControlProgram | None:
    """The program a client sent, if it is ur-rtde's control script.

    Args:
        text: the program, `def name():` to its last `end`.

    Returns:
        The program to run, or None for any other program (not modelled).
    """
    if not text.startswith("def rtde_control():") or "read_input_integer_register" not in text:
        return None
    offsets = {kind: int(value) for kind, value in _OFFSET.findall(text)}
    return ControlProgram(offsets.get("int", 0), offsets.get("float", 0))
