"""Universal Robots through ur-rtde (the `ur` extra) as an Arm: servoJ at the servo rate, the
measured joints from RTDE's actual_q, the controller-side RTDE watchdog armed, so that the
controller stops the program itself when the stream stops (a sender that hangs, a cable
pulled)."""

from __future__ import annotations

import os
import sys
import tempfile
from typing import Any

import numpy as np

from articula.arms.arm import Measured
from articula.errors import ConfigError, DeviceError

__all__ = ["GAIN", "LOOKAHEAD", "WATCHDOG_HZ", "URArm"]

LOOKAHEAD = 0.03  # [s] servoj's lookahead_time, its least: the stream is already jerk-limited
GAIN = 500.0  # servoj's gain (UR's range 100–2000)
WATCHDOG_HZ = 10.0  # [Hz] the controller stops the program after 100 ms without a set-point
VARIABLES = ["timestamp", "actual_q", "actual_qd", "runtime_state", "safety_status_bits"]
PROTECTIVE_BIT = 2  # safety_status_bits: protective stop
PLAYING = 2  # runtime_state


class URArm:
    """A UR arm (e-Series, PolyScope 5) behind its controller's RTDE interface.

    Args:
        host: the controller's address.
        rate: the servo rate [Hz] (500 for an e-Series, 125 for a CB3).

    Attributes:
        rate: the servo rate [Hz].
        host: the controller's address.
        messages: the lines ur-rtde's C++ client wrote while connected (kept off the terminal,
            whose lines are the command's own; a drive keeps them in its record).
    """

    def __init__(self, host: str, rate: float = 500.0) -> None:
        self.host, self.rate = host, float(rate)
        self._control: Any = None
        self._receive: Any = None
        self.messages: list[str] = []
        self._output = _Output()

    def connect(self) -> Measured:
        """Connect RTDE (receive, then control: ur-rtde uploads its control program), arm
        the watchdog.

        Returns:
            The first measurement.

        Raises:
            ConfigError: ur-rtde is not installed (naming the extra).
            DeviceError: nothing answers at the address, or the program does not start.
        """
        try:
            import rtde_control
            import rtde_receive
        except ImportError as exc:
            raise ConfigError(
                "--arm", f'ur: needs ur-rtde: pip install "articula[ur]" ({exc})'
            ) from None
        self._output.capture()
        try:
            self._receive = rtde_receive.RTDEReceiveInterface(self.host, self.rate, VARIABLES)
            self._control = rtde_control.RTDEControlInterface(self.host, self.rate)
            if not self._control.setWatchdog(WATCHDOG_HZ):
                raise DeviceError(
                    f"ur:{self.host}: the controller refused setWatchdog ({self._why()})"
                )
            return self.read()
        except RuntimeError as exc:
            self.messages += self._output.release()
            raise DeviceError(f"ur:{self.host}: cannot connect ({exc})") from None
        except BaseException:
            self.messages += self._output.release()
            raise

    def read(self) -> Measured:
        """The latest RTDE state.

        Returns:
            The controller's timestamp [s] and actual_q [rad].

        Raises:
            DeviceError: the connection is lost.
        """
        if not self._receive.isConnected():
            raise DeviceError(f"ur:{self.host}: the RTDE connection was lost")
        return Measured(self._receive.getTimestamp(), np.array(self._receive.getActualQ()))

    def send(self, q: np.ndarray, qd: np.ndarray) -> None:
        """servoJ toward q + qd · LOOKAHEAD: the set-point predicted by servoj's lookahead
        time, so that its smoothing (a lag of about that time) does not delay the stream.

        Args:
            q: joint positions, shape (6,) [rad].
            qd: joint velocities, shape (6,) [rad/s].

        Raises:
            DeviceError: the controller refused it (a protective stop, the program stopped)
                or the connection is lost.
        """
        try:
            target = [float(v) for v in np.asarray(q) + LOOKAHEAD * np.asarray(qd)]
            ok = self._control.servoJ(target, 0.0, 0.0, 1.0 / self.rate, LOOKAHEAD, GAIN)
        except RuntimeError as exc:
            raise DeviceError(f"ur:{self.host}: servoJ failed ({exc})") from None
        if not ok:
            raise DeviceError(f"ur:{self.host}: the controller refused servoJ ({self._why()})")

    def stop(self) -> None:
        """Stop servoing (the controller brakes whatever motion is left) and the program."""
        try:
            self._control.servoStop()
            self._control.stopScript()
        except RuntimeError as exc:
            raise DeviceError(f"ur:{self.host}: stopping failed ({exc})") from None

    def close(self) -> None:
        """Disconnect both interfaces; the client's output is the terminal's again."""
        try:
            for interface in (self._control, self._receive):
                if interface is not None:
                    interface.disconnect()
        finally:
            self.messages += self._output.release()

    def _why(self) -> str:
        """What the controller's state says about a refusal."""
        if not self._receive.isConnected():
            return "the RTDE connection was lost"
        if int(self._receive.getSafetyStatusBits()) & (1 << PROTECTIVE_BIT):
            return "a protective stop; see the controller's log"
        if int(self._receive.getRuntimeState()) != PLAYING:
            return "its program is not running"
        return "no reason given"


class _Output:
    """File descriptors 1 and 2 sent to a temporary file while capturing, Python's own
    sys.stdout and sys.stderr kept on the terminal: only what the C++ client writes (its
    reconnect attempts and exceptions, as many lines as it likes) is captured."""

    def __init__(self) -> None:
        self._saved: list[tuple[int, int, Any]] = []  # (fd, its copy, Python's stream)
        self._file: Any = None

    def capture(self) -> None:
        if self._saved:
            return
        self._file = tempfile.TemporaryFile()  # noqa: SIM115  (closed by release)
        for fd, name in ((1, "stdout"), (2, "stderr")):
            stream = getattr(sys, name)
            stream.flush()
            copy = os.dup(fd)
            self._saved.append((fd, copy, stream))
            os.dup2(self._file.fileno(), fd)
            setattr(sys, name, open(os.dup(copy), "w", buffering=1, closefd=True))  # noqa: SIM115

    def release(self) -> list[str]:
        """Stop capturing.

        Returns:
            The lines the client wrote meanwhile.
        """
        if not self._saved:
            return []
        for fd, copy, stream in self._saved:
            name = "stdout" if fd == 1 else "stderr"
            getattr(sys, name).close()
            setattr(sys, name, stream)
            os.dup2(copy, fd)
            os.close(copy)
        self._saved.clear()
        self._file.seek(0)
        lines = self._file.read().decode("utf-8", "replace").splitlines()
        self._file.close()
        return [line for line in lines if line.strip()]
