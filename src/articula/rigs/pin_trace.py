"""What a logic analyser on the emulated board sees: the harness's trace (`--trace`), read
back as the output registers over time and the frames on the host's line.

The harness writes a line whenever a traced register changes ("pins"), per frame the host
sent as it ends on the line ("rx") and per frame the firmware sent as its delimiter goes out
("tx"), per byte its USART lost ("overrun"), at a run's start and end, a reset and a hang,
and each time a section with interrupts off is the longest yet ("irqoff"). Times are CPU
cycles at 16 MHz. `active_outputs` says, per rig, which outputs are driven in a register
state: anything but the safe state of docs/protocol.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from articula.errors import DeviceError
from articula.rigs import protocol
from articula.rigs.protocol import Frame

CPU_HZ = 16_000_000
COM_A1 = 0x80  # COMnA1 in TCCRnA: the compare output drives its pin (PWM on the pin)


@dataclass(frozen=True)
class PinState:
    """The traced output registers from `cycle` on.

    Attributes:
        cycle: when they took these values [CPU cycles].
        porta: PORTA (motor: IN1-IN4 on bits 2-5; six-chamber: chambers 0-3's coils).
        portb: PORTB (PneuNet: the valve's pin, bit 5).
        portc: PORTC (six-chamber: chambers 4-5's coils, bits 4-7).
        porte: PORTE (motor: ENA, bit 3).
        porth: PORTH (motor: ENB, bit 3; PneuNet and six-chamber: the pump, bit 5).
        tccr1a: Timer1's control register A (COM1A1: PWM on the PneuNet's valve pin).
        tccr3a: Timer3's control register A (COM3A1: PWM on ENA).
        tccr4a: Timer4's control register A (COM4A1: PWM on ENB).
        ocr1a: Timer1's compare register A (the valve's duty) [ticks].
        ocr3a: Timer3's compare register A (ENA's duty) [counts].
        ocr4a: Timer4's compare register A (ENB's duty) [counts].
    """

    cycle: int
    porta: int
    portb: int
    portc: int
    porte: int
    porth: int
    tccr1a: int
    tccr3a: int
    tccr4a: int
    ocr1a: int
    ocr3a: int
    ocr4a: int


@dataclass(frozen=True)
class LineFrame:
    """A frame on the host's line, as the trace timed it.

    Attributes:
        cycle: when its delimiter ended on the line (host) or went out (firmware) [cycles].
        from_host: True for the host's frames, False for the firmware's.
        frame: the frame decoded; None when it does not decode (damaged or cut).
    """

    cycle: int
    from_host: bool
    frame: Frame | None


@dataclass(frozen=True)
class InterruptsOff:
    """A section with interrupts off (SREG's I bit clear), the longest since the harness
    started when it ended.

    Attributes:
        cycle: when it ended [CPU cycles].
        cycles: its length, as simavr counts it (the chip's 5-cycle interrupt response not
            included) [CPU cycles].
        address: the flash byte address it began at: after its `cli`, or an interrupt's
            vector.
    """

    cycle: int
    cycles: int
    address: int


def active_outputs(program: str, state: PinState) -> list[str]:
    """The outputs `state` drives, by name; [] in the safe state.

    A pin counts as driven when its PORT bit is set (driven high, or its pull-up on) or its
    timer's compare output is connected to it (a fast PWM pulses even at duty 0).

    Args:
        program: "motor", "pneunet" or "six_chamber".
        state: the output registers.

    Returns:
        The names of the active outputs: motor ENA, ENB, IN1-IN4; PneuNet valve, pump;
        six-chamber pump and each chamber's fill coil (its vent coil is the safe state).
    """
    s, on = state, []
    if program == "motor":
        on += ["ENA"] * bool(s.tccr3a & COM_A1 or s.porte & 0x08)
        on += ["ENB"] * bool(s.tccr4a & COM_A1 or s.porth & 0x08)
        on += [f"IN{k + 1}" for k in range(4) if s.porta >> (2 + k) & 1]
    elif program == "pneunet":
        on += ["valve"] * bool(s.tccr1a & COM_A1 or s.portb & 0x20)
        on += ["pump"] * bool(s.porth & 0x20)
    else:
        on += ["pump"] * bool(s.porth & 0x20)
        on += [f"fill{c}" for c in range(4) if s.porta >> (2 * c) & 1]
        on += [f"fill{4 + k}" for k, bit in enumerate((7, 5)) if s.portc >> bit & 1]
    return on


class PinTrace:
    """The harness's trace file, read as it grows.

    Args:
        path: the file the harness writes (`FirmwareRig(trace=...)`).
    """

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.pins: list[PinState] = []
        self.frames: list[LineFrame] = []
        self.events: list[
            tuple[str, int]
        ] = []  # ("run" | "end" | "reset" | "hang" | "overrun", cycle)
        self.interrupts_off: list[InterruptsOff] = []  # each the longest yet, in order
        self._offset = 0

    def update(self) -> PinTrace:
        """Read what the harness wrote since the last call (whole lines only).

        Returns:
            The trace itself.
        """
        with self.path.open("rb") as f:
            f.seek(self._offset)
            data = f.read()
        complete = data.rfind(b"\n") + 1
        self._offset += complete
        for line in data[:complete].decode("ascii").splitlines():
            what, cycle, *rest = line.split()
            if what == "pins":
                self.pins.append(PinState(int(cycle), *map(int, rest)))
            elif what == "irqoff":
                off = InterruptsOff(int(cycle), int(rest[0]), int(rest[1], 16))
                self.interrupts_off.append(off)
            elif what in ("rx", "tx"):
                self.frames.append(LineFrame(int(cycle), what == "rx", _decode(rest)))
            else:
                self.events.append((what, int(cycle)))
        return self

    def state_at(self, cycle: int) -> PinState:
        """The registers at `cycle` (the last change at or before it).

        Args:
            cycle: a time [CPU cycles].

        Returns:
            The state then.
        """
        before = [p for p in self.pins if p.cycle <= cycle]
        return before[-1] if before else self.pins[0]

    def safe_from(self, program: str, cycle: int) -> int | None:
        """The first time at or after `cycle` from which no output is active up to the
        trace's end; None when an output is active at its end.

        Args:
            program: "motor", "pneunet" or "six_chamber".
            cycle: where to look from [CPU cycles].

        Returns:
            That time [CPU cycles], or None.
        """
        states = [self.state_at(cycle)] + [p for p in self.pins if p.cycle > cycle]
        safe = None
        for state in states:
            if active_outputs(program, state):
                safe = None
            elif safe is None:
                safe = max(state.cycle, cycle)
        return safe


def _decode(rest: list[str]) -> Frame | None:
    """A traced frame's bytes decoded; None when they do not decode."""
    try:
        return protocol.decode(bytes.fromhex(rest[0])) if rest else None
    except (DeviceError, ValueError):
        return None
