"""A firmware file checked before the AVR emulator starts: an ELF, for the AVR, and the
program of the rig it is to run.

articula's programs (firmware/) name themselves in a section `.articula` that is not
loaded into the chip ("articula program=motor"): `make` puts it there, a HEX file and the
flash do not carry it. Anything else (an empty file, random bytes, an ELF for another
processor, another rig's program) is refused by name before simavr sees it.
"""

from __future__ import annotations

import struct
from pathlib import Path

from articula.errors import ConfigError

EM_AVR = 83  # the ELF machine number of Atmel AVR
MAX_BYTES = 16 * 1024 * 1024  # far beyond any ATmega2560 program with its debug sections
SECTION = b".articula"
MACHINES = {3: "x86", 40: "ARM", 62: "x86-64", 183: "AArch64", 243: "RISC-V"}


def check_firmware(path: Path, program: str) -> None:
    """ConfigError (field --firmware) unless `path` is articula's `program` for the AVR.

    Args:
        path: the firmware file (an ELF, e.g. firmware/build/motor.elf).
        program: the rig program it must be: "motor", "pneunet" or "six_chamber".
    """
    fix = f"use firmware/build/{program}.elf (make -C firmware)"
    try:
        size = path.stat().st_size
        data = path.read_bytes() if size <= MAX_BYTES else b""
    except OSError as exc:
        raise ConfigError("--firmware", f"{path}: {exc.strerror}; {fix}") from None
    if size == 0:
        raise ConfigError("--firmware", f"{path} is empty, not a firmware ELF; {fix}")
    if size > MAX_BYTES:
        raise ConfigError(
            "--firmware", f"{path} holds {size} bytes, more than any ATmega2560 firmware ELF; {fix}"
        )
    if data[:4] != b"\x7fELF":
        raise ConfigError(
            "--firmware", f"{path} is not an ELF file (it starts with {data[:4].hex(' ')}); {fix}"
        )
    machine = (
        struct.unpack_from("<H" if data[5:6] != b"\2" else ">H", data, 18)[0]
        if len(data) >= 20
        else None
    )
    if machine is not None and machine != EM_AVR:
        name = MACHINES.get(machine, f"machine {machine}")
        raise ConfigError("--firmware", f"{path} is an ELF for {name}, not for the AVR; {fix}")
    if len(data) < 52 or data[4] != 1 or data[5] != 1:
        raise ConfigError(
            "--firmware", f"{path} is not a 32-bit little-endian ELF, as avr-gcc makes; {fix}"
        )
    found = _named_program(data)
    if found is None:
        raise ConfigError(
            "--firmware",
            f"{path} is an AVR ELF but not articula's rig "
            f"firmware (no {SECTION.decode()} section); {fix}",
        )
    if found != program:
        raise ConfigError(
            "--firmware", f"{path} is the {found} firmware, not the {program} rig's; {fix}"
        )


def _named_program(data: bytes) -> str | None:
    """The program named in the ELF's .articula section; None without one (or a section
    table that does not read)."""
    try:
        (shoff,) = struct.unpack_from("<I", data, 32)
        entsize, count, names = struct.unpack_from("<HHH", data, 46)
        sections = [struct.unpack_from("<IIIIII", data, shoff + k * entsize) for k in range(count)]
        table = sections[names]
        strings = data[table[4] : table[4] + table[5]]
        for name, _, _, _, offset, size in sections:
            if strings[name:].split(b"\0", 1)[0] == SECTION:
                words = data[offset : offset + size].rstrip(b"\0").decode("ascii").split()
                fields = dict(word.split("=", 1) for word in words if "=" in word)
                return fields.get("program")
    except (struct.error, IndexError, UnicodeDecodeError):
        return None
    return None
