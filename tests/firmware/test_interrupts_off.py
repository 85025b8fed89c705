"""tools/interrupts_off.py bounds every section of an AVR program that runs with interrupts
off (issue 47): on the rigs' firmware, within a byte's time at 1 Mbaud (160 cycles); on small
programs, exactly the cycles the datasheet gives, the longer way of a branch, a callee to its
ret, an interrupt's entry, and what the harness's trace measures; and a loop or an indirect
call has no bound."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.firmware
TOOL = Path(__file__).resolve().parents[2] / "tools/interrupts_off.py"
_spec = importlib.util.spec_from_file_location("interrupts_off", TOOL)
interrupts_off = sys.modules["interrupts_off"] = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(interrupts_off)


def _program(tmp_path: Path, source: str) -> Path:
    """`source` built for the ATmega2560 as the firmware is (-Os)."""
    c = tmp_path / "program.c"
    c.write_text(source)
    elf = tmp_path / "program.elf"
    subprocess.run(["avr-gcc", "-mmcu=atmega2560", "-DF_CPU=16000000UL", "-Os", "-o", elf, c],
                   check=True)  # fmt: skip
    return elf


def _sections(elf: Path, function: str) -> list[dict]:
    """The sections the tool finds in `function`."""
    return [s for s in interrupts_off.report(elf)["sections"] if s["function"] == function]


@pytest.mark.parametrize("name", ["motor", "pneunet", "six_chamber"])
def test_every_section_of_the_rigs_firmware_is_shorter_than_a_byte(built, name):
    result = interrupts_off.report(built / f"{name}.elf")
    assert [s for s in result["sections"] if s["cycles"] is None] == []
    assert 0 < result["max_cycles"] <= interrupts_off.BYTE_CYCLES


def test_a_straight_section_counts_what_the_datasheet_gives(built, tmp_path):
    # After the cli: nop 1, lds 2, sts 2, rjmp 2, push 2, pop 2, sei 1.
    elf = _program(tmp_path, r"""
        int main(void) {
            __asm__ volatile("cli\n nop\n lds r24, 0x200\n sts 0x200, r24\n rjmp 1f\n"
                             "1: push r24\n pop r24\n sei" ::: "r24");
            for (;;) {}
        }""")  # fmt: skip
    assert [s["cycles"] for s in _sections(elf, "main")] == [12]


def test_a_branch_counts_its_longer_way_and_a_call_its_callee(built, tmp_path):
    # breq taken (2) to a call (5) of f: nop, ret (1 + 5); then sei (1): 14. Not taken: the
    # breq (1), 5 nops (objdump's "..." for zero words: disassembled), rjmp (2), sei: 9.
    elf = _program(tmp_path, r"""
        void f(void) __attribute__((naked, noinline, used));
        void f(void) { __asm__ volatile("nop\n ret"); }
        int main(void) {
            __asm__ volatile("cli\n breq 1f\n nop\n nop\n nop\n nop\n nop\n rjmp 2f\n"
                             "1: call f\n 2: sei");
            for (;;) {}
        }""")  # fmt: skip
    assert [s["cycles"] for s in _sections(elf, "main")] == [2 + 5 + 6 + 1]


def test_an_interrupt_counts_its_entry_to_its_reti(built, tmp_path):
    # The chip's response and the vector's jmp (8), two nops, reti (5).
    elf = _program(tmp_path, r"""
        #include <avr/interrupt.h>
        ISR(INT0_vect, ISR_NAKED) { __asm__ volatile("nop\n nop\n reti"); }
        int main(void) { for (;;) {} }""")  # fmt: skip
    assert [s["cycles"] for s in _sections(elf, "__vector_1")] == [8 + 2 + 5]


@pytest.mark.parametrize(
    ("body", "why"),
    [
        ("for (uint8_t k = 0; k < n; k++) PORTB ^= 1;", "a loop"),
        ("hook();", "icall"),
    ],
)
def test_a_loop_or_an_indirect_call_has_no_bound(built, tmp_path, body, why):
    elf = _program(tmp_path, rf"""
        #include <avr/interrupt.h>
        volatile uint8_t n;
        void (*volatile hook)(void);
        int main(void) {{
            cli();
            {body}
            sei();
            for (;;) {{}}
        }}""")  # fmt: skip
    [section] = _sections(elf, "main")
    assert section["cycles"] is None and why in section["why"]
    assert interrupts_off.report(elf)["max_cycles"] is None


def test_the_harness_measures_a_section_as_the_tool_counts_it(built, tmp_path):
    # A cli, 20 nops and a sei, over and over: 21 cycles each time, by both.
    nops = "nop\\n" * 20
    elf = _program(tmp_path, rf"""
        #include <avr/interrupt.h>
        int main(void) {{
            sei();
            for (;;) __asm__ volatile("cli\n {nops} sei");
        }}""")  # fmt: skip
    trace = tmp_path / "program.trace"
    proc = subprocess.Popen([built / "harness", elf, "--trace", trace], stdout=subprocess.PIPE,
                            text=True)  # fmt: skip
    try:  # the harness says where its UART is after 20 ms of the program: sections by then
        next(line for line in proc.stdout if line.startswith("uart0 at "))
    finally:
        proc.kill()
        proc.wait(10)
    measured = [int(line.split()[2]) for line in trace.read_text().splitlines()
                if line.startswith("irqoff")]  # fmt: skip
    assert measured == [21] == [s["cycles"] for s in _sections(elf, "main")]
