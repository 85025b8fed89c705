"""A rig's own firmware (firmware/, C for the ATmega2560) run in the simavr harness, its pins
coupled in lock step to the simulated plant: `articula emulate RIG --firmware ELF`.

The harness (firmware/harness/harness.c) runs the ELF cycle by cycle and puts its UART0
behind a pseudo-terminal, the path the host opens. Every ADC conversion the firmware starts
is one control period of the plant: the harness reports the output registers the firmware
left (port and PWM compare registers) and takes back the ADC code the conversion reads, the
count the quadrature encoder reaches and the bytes a sensor sends on Serial1. A plant without
an ADC reading (the six-chamber rig's) steps on its own clock instead (`tick_us`), the
harness reading the valve pins each step. The plant is the Python model of the in-process
simulation (a `PinPlant`); it starts from rest with the run's seed when the firmware starts
a run.
"""

from __future__ import annotations

import contextlib
import signal
import subprocess
import threading
from pathlib import Path
from typing import NamedTuple, Protocol

from articula.errors import ConfigError, DeviceError
from articula.rigs.elf import check_firmware

BUILD_HINT = (
    "build it with: make -C firmware (needs apt-get install -y gcc-avr avr-libc "
    "simavr libsimavr-dev)"
)


class Pins(NamedTuple):
    """The firmware's outputs at the start of a control period, as the harness reads them.

    Attributes:
        adc_channel: the ADC channel the starting conversion reads (255: a tick, no conversion).
        porta: PORTA register: H-bridge direction and valve pins.
        portc: PORTC register: valve pins.
        porth: PORTH register: the PneuNet's pump pin.
        ocr1a: Timer1's PWM compare register (duty) [counts].
        ocr3a: Timer3's PWM compare register (duty) [counts].
        ocr4a: Timer4's PWM compare register (duty) [counts].
        step_cycles: CPU cycles the previous control step took (its marked interrupts
            and its main-loop part, interrupts that came meanwhile included).
        step_latency: CPU cycles from the previous sample's interrupt to the end of its
            main-loop control step (0 for a rig without one).
    """

    adc_channel: int
    porta: int
    portc: int
    porth: int
    ocr1a: int
    ocr3a: int
    ocr4a: int
    step_cycles: int
    step_latency: int


class Inputs(NamedTuple):
    """What the plant puts on the firmware's inputs for the period that starts.

    Attributes:
        adc_code: the code the starting ADC conversion reads [counts].
        encoder_count: where the quadrature encoder on D2/D3 goes [counts].
        serial1: the bytes a sensor sends on Serial1 now.
    """

    adc_code: int = 0
    encoder_count: int = 0
    serial1: bytes = b""


class PinPlant(Protocol):
    """A simulated plant behind the firmware's pins."""

    tick_us: int | None  # the plant's own step [µs]; None: a step per ADC conversion
    program: str  # the firmware it is built for: "motor", "pneunet" or "six_chamber"

    def start(self, seed: int) -> None:
        """A run starts: the plant at rest, its noise drawn from `seed`.

        Args:
            seed: the run's noise seed (START's).
        """

    def period(self, pins: Pins) -> Inputs:
        """One control period: the outputs `pins` held since the last call act on the plant
        (none before the first).

        Args:
            pins: the firmware's outputs as the harness reads them now (held since the last call).

        Returns:
            The plant's inputs to the firmware at the period's start.
        """


class FirmwareRig:
    """A firmware ELF in the harness with its plant; `path` is the port the host opens.

    The ELF is checked first (rigs/elf.py: an AVR ELF of articula's program for the plant's
    rig; ConfigError naming the file otherwise), so simavr never sees another file.

    Args:
        elf: the firmware (firmware/build/<rig>.elf); the harness is found beside it.
        plant: the simulated plant its pins drive and read.
        realtime: keep the wall clock's pace during runs (default: as fast as it goes).
        trace: a file for the harness's trace of the pins and the line (rigs/pin_trace.py);
            None: no trace.
    """

    def __init__(
        self, elf: Path, plant: PinPlant, realtime: bool = False, trace: Path | None = None
    ) -> None:
        elf = Path(elf)
        harness = elf.parent / "harness"
        if not elf.is_file():
            raise ConfigError("--firmware", f"{elf} does not exist; {BUILD_HINT}")
        check_firmware(elf, plant.program)
        if not harness.is_file():
            raise ConfigError(
                "--firmware", f"{harness} does not exist beside {elf.name}; {BUILD_HINT}"
            )
        self.plant = plant
        self.step_cycles: list[int] = []  # per control period of the last run
        self.step_latency: list[int] = []
        args = [str(harness), str(elf), "--plant"] + (["--realtime"] if realtime else [])
        if plant.tick_us is not None:
            args += ["--tick-us", str(plant.tick_us)]
        if trace is not None:
            args += ["--trace", str(trace)]
        self._proc = subprocess.Popen(
            args, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1
        )
        self.path = self._read_path()
        self._thread = threading.Thread(target=self._serve, name="articula-plant", daemon=True)
        self._thread.start()

    def _read_path(self) -> str:
        """The harness's first words: where its UART0 is."""
        for line in self._proc.stdout:
            if line.startswith("uart0 at "):
                return line.split()[-1]
        code = self._proc.wait()
        raise DeviceError(f"the firmware harness ended before its UART came up (exit {code})")

    def _serve(self) -> None:
        """Answer the harness's periods until it ends."""
        for line in self._proc.stdout:
            word, *numbers = line.split()
            if word == "run":
                self.plant.start(int(numbers[0]))
                self.step_cycles, self.step_latency = [], []
            elif word == "sample":
                pins = Pins(*map(int, numbers))
                self.step_cycles.append(pins.step_cycles)
                self.step_latency.append(pins.step_latency)
                inputs = self.plant.period(pins)
                reply = f"{inputs.adc_code} {inputs.encoder_count} {inputs.serial1.hex()}\n"
                try:
                    self._proc.stdin.write(reply)
                    self._proc.stdin.flush()
                except (BrokenPipeError, ValueError):
                    return  # the harness is gone

    def reset(self) -> None:
        """Reset the board, as its reset button does: the firmware starts again (and says so
        with an INFO unasked); a run going on ends."""
        self._proc.send_signal(signal.SIGUSR1)

    def hang(self) -> None:
        """Hang the firmware's main loop, as a bug's endless loop would (its interrupts go
        on): the watchdog should put the outputs off and reset the board."""
        self._proc.send_signal(signal.SIGUSR2)

    def close(self) -> None:
        """Stop the harness (the port goes away)."""
        self._proc.kill()
        self._proc.wait()
        self._thread.join(timeout=2.0)
        for stream in (self._proc.stdin, self._proc.stdout):
            with contextlib.suppress(BrokenPipeError, OSError):
                stream.close()

    def __enter__(self) -> FirmwareRig:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
