"""The longest path through every section of an AVR ELF that runs with interrupts off,
counted in CPU cycles from its disassembly (avr-objdump): a bound that holds for any input,
beside the harness's measurement of the runs it saw (docs/guides/firmware.md).

    python tools/interrupts_off.py firmware/build/motor.elf [more.elf ...] [--json] [--limit 160]

A section begins after a `cli`, or at an interrupt's entry (a `__vector_N` function: the
chip clears I as it takes the interrupt, 5 cycles to respond with a 3-byte PC and 3 for the
vector's `jmp`, counted in), and ends at the first instruction that sets I again: `sei`,
`reti`, or, for a `cli` right after `in rN, 0x3f` (ATOMIC_RESTORESTATE, a stack frame's
change), the `out 0x3f, rN` that restores that SREG. Any other SREG write (an interrupt's
epilogue restoring what its prologue saved, I clear) does not end a section. Every path is
followed:
both ways of a branch or skip, the longest taken; a call into its callee, to its `ret`. The
count includes the instruction that ends the section, not the one the chip still runs after
a `sei` before it takes an interrupt. Cycles are the ATmega2560's (AVRe+, 22-bit PC: call 5,
ret and reti 5, rcall and icall 4). A section with a loop, an indirect call or jump, or one
that returns with interrupts off has no bound here and is an error: the firmware keeps every
section straight-line so that it can be bounded. avr-libc's `exit` (`cli`, then a jump to
itself, reached only if main returned) is a halt, not a section.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

BYTE_CYCLES = 160  # a byte's time on the line at 1 Mbaud: 10 bits at 16 MHz
INTERRUPT_ENTRY = 5 + 3  # [cycles] the chip's response (3-byte PC) and the vector's jmp
SREG = "0x3f"
HALTS = {"exit", "_exit"}  # avr-libc's: cli, then a jump to itself
LINE = re.compile(
    r"^\s*([0-9a-f]+):\t((?:[0-9a-f]{2} )+)\s*\t(\S+)\s*([^;]*)(?:;\s*0x([0-9a-f]+))?"
)
LABEL = re.compile(r"^([0-9a-f]+) <(.+)>:$")
TWO = {"adiw", "sbiw", "mul", "muls", "mulsu", "fmul", "fmuls", "fmulsu", "ldd", "lds", "std",
       "sts", "push", "pop", "rjmp", "ijmp", "eijmp", "cbi", "sbi", "st", "ld"}  # fmt: skip
CYCLES = {"jmp": 3, "lpm": 3, "elpm": 3, "call": 5, "rcall": 4, "icall": 4, "eicall": 4,
          "ret": 5, "reti": 5}  # fmt: skip
SKIPS = {"sbrc", "sbrs", "sbic", "sbis", "cpse"}
INDIRECT = {"icall", "eicall", "ijmp", "eijmp"}
CALLEE = "callee"  # a path in a function called in a section, to its ret (Program._longest)


class UnboundedError(Exception):
    """A section whose longest path cannot be counted (a loop, an indirect call)."""


@dataclass(frozen=True)
class Instruction:
    """One disassembled instruction.

    Attributes:
        address: its flash byte address.
        size: its length [bytes] (2 or 4).
        op: the mnemonic.
        args: the operands as avr-objdump prints them.
        target: the flash byte address a branch, jump or call goes to; None otherwise.
    """

    address: int
    size: int
    op: str
    args: str
    target: int | None

    @property
    def cycles(self) -> int:
        """Its cycles when it does not branch or skip [CPU cycles]."""
        if self.op == "ld" and "-" in self.args:
            return 3  # pre-decrement
        return CYCLES.get(self.op, 2 if self.op in TWO else 1)

    @property
    def restores_sreg(self) -> bool:
        """It writes SREG (`out 0x3f, rN`): a restore of a saved SREG."""
        return self.op == "out" and self.args.split(",")[0].strip() == SREG


@dataclass(frozen=True)
class Section:
    """A section with interrupts off and its longest path.

    Attributes:
        function: the function it lies in.
        begins: the flash byte address of its first instruction (after the `cli`, or the
            interrupt's entry).
        kind: "cli" or "interrupt".
        cycles: its longest path [CPU cycles]; None when it has no bound.
        why: why not, for a section without a bound; "" otherwise.
    """

    function: str
    begins: int
    kind: str
    cycles: int | None
    why: str


class Program:
    """An ELF's code, disassembled, and the longest paths through it.

    Args:
        elf: the AVR ELF file.
    """

    def __init__(self, elf: Path) -> None:
        listing = subprocess.run(["avr-objdump", "-d", "-z", str(elf)], capture_output=True,
                                 text=True, check=True).stdout  # fmt: skip
        self.code: dict[int, Instruction] = {}
        self.functions: dict[int, str] = {}
        for line in listing.splitlines():
            if label := LABEL.match(line):
                self.functions[int(label[1], 16)] = label[2]
            elif m := LINE.match(line):
                address = int(m[1], 16)
                target = int(m[5], 16) if m[5] else None
                self.code[address] = Instruction(
                    address, len(m[2].split()), m[3], m[4].strip(), target
                )
        self._starts = sorted(self.functions)
        self._memo: dict[tuple[int, str], int] = {}

    def function_at(self, address: int) -> str:
        """The function an address lies in (the nearest label at or before it)."""
        at = max((s for s in self._starts if s <= address), default=None)
        return self.functions.get(at, "?")

    def sections(self) -> list[Section]:
        """Every section with interrupts off, its longest path counted."""
        found = []
        before = None
        for address, ins in sorted(self.code.items()):
            name = self.function_at(address)
            if ins.op == "cli" and name not in HALTS:
                saved = before.args.split(",")[0].strip() if _saves_sreg(before) else ""
                found.append(self._section(name, address + ins.size, "cli", 0, saved))
            before = ins
        for address, name in sorted(self.functions.items()):
            if name.startswith("__vector_") and address in self.code:
                found.append(self._section(name, address, "interrupt", INTERRUPT_ENTRY, ""))
        return found

    def _section(self, function: str, begins: int, kind: str, entry: int, saved: str) -> Section:
        """One section from `begins`, `entry` cycles already spent; `saved`: the register
        whose restore into SREG ends it ("": none does)."""
        try:
            return Section(function, begins, kind, entry + self._longest(begins, saved, ()), "")
        except UnboundedError as exc:
            return Section(function, begins, kind, None, str(exc))

    def _longest(self, address: int, mode: str, path: tuple[int, ...]) -> int:
        """The longest path from `address` to the section's end [CPU cycles]. `mode`: the
        register whose `out 0x3f` ends the section ("": none), or CALLEE (a function called
        in a section: to its `ret`, its SREG writes only restoring what it found)."""
        key = (address, mode)
        if key in self._memo:
            return self._memo[key]
        if address in path:
            raise UnboundedError(f"a loop at 0x{address:x} ({self.function_at(address)})")
        ins = self.code.get(address)
        if ins is None:
            raise UnboundedError(f"no instruction at 0x{address:x}")
        path = (*path, address)
        if ins.op in INDIRECT:
            raise UnboundedError(f"{ins.op} at 0x{address:x}: its target is not in the code")
        ends = ins.op in ("sei", "reti") or (ins.restores_sreg and ins.args.endswith(f" {mode}"))
        if (ins.op in ("ret", "reti") and mode == CALLEE) or (ends and mode != CALLEE):
            cycles = ins.cycles
        elif ins.op == "ret":
            raise UnboundedError(f"{self.function_at(address)} returns with interrupts off")
        else:
            steps = self._next(ins, path)
            cycles = max(cost + self._longest(to, mode, path) for to, cost in steps)
        self._memo[key] = cycles
        return cycles

    def _next(self, ins: Instruction, path: tuple[int, ...]) -> list[tuple[int, int]]:
        """Where execution goes after `ins`, and what getting there costs (the callee's
        whole path for a call) [CPU cycles]."""
        after = ins.address + ins.size
        if ins.op in ("call", "rcall"):
            return [(after, ins.cycles + self._longest(ins.target, CALLEE, path))]
        if ins.op in ("jmp", "rjmp"):
            return [(ins.target, ins.cycles)]
        if ins.op.startswith("br") and ins.target is not None:
            return [(after, 1), (ins.target, 2)]
        if ins.op in SKIPS:
            skipped = self.code[after]
            return [(after, 1), (after + skipped.size, 1 + skipped.size // 2)]
        return [(after, ins.cycles)]


def _saves_sreg(ins: Instruction | None) -> bool:
    """`ins` is `in rN, 0x3f`: SREG saved into a register."""
    return ins is not None and ins.op == "in" and ins.args.split(",")[-1].strip() == SREG


def _unbounded_first(section: Section) -> tuple[bool, int]:
    """Sort key: sections without a bound, then the longest."""
    return section.cycles is not None, -(section.cycles or 0)


def report(elf: Path) -> dict:
    """An ELF's sections with interrupts off, the longest first, and their maximum.

    Args:
        elf: the AVR ELF file.

    Returns:
        {"max_cycles": the longest bound (None when a section has none), "sections": each
        as Section's fields}.
    """
    sections = sorted(Program(elf).sections(), key=_unbounded_first)
    bounded = [s.cycles for s in sections]
    worst = None if None in bounded else max(bounded, default=0)
    return {"max_cycles": worst, "sections": [asdict(s) for s in sections]}


def _table(name: str, result: dict, rows: int) -> str:
    """The longest sections as a Markdown table."""
    lines = [f"{name}: longest {result['max_cycles']} cycles", "",
             "| cycles | section | begins at |", "|---:|---|---|"]  # fmt: skip
    for s in result["sections"][:rows]:
        cycles = s["cycles"] if s["cycles"] is not None else f"no bound: {s['why']}"
        what = "interrupt" if s["kind"] == "interrupt" else "cli in"
        lines.append(f"| {cycles} | {what} `{s['function']}` | 0x{s['begins']:x} |")
    return "\n".join(lines)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("elves", nargs="+", type=Path, help="AVR ELF files")
    parser.add_argument("--json", action="store_true", help="print JSON, every section")
    parser.add_argument("--rows", type=int, default=8, help="sections a table shows")
    parser.add_argument("--limit", type=int, default=BYTE_CYCLES,
                        help="exit status 1 when a section may be longer (default: a byte "
                        "at 1 Mbaud, 160)")  # fmt: skip
    args = parser.parse_args()
    results = {elf.stem: report(elf) for elf in args.elves}
    if args.json:
        print(json.dumps(results, indent=1))
    else:
        print("\n\n".join(_table(name, r, args.rows) for name, r in results.items()))
    over = [r["max_cycles"] is None or r["max_cycles"] > args.limit for r in results.values()]
    sys.exit(1 if any(over) else 0)
