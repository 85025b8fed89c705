"""The bench rigs of chapters 2-4 over USB serial: protocol, link, host drivers, emulators."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "elf",
    "emulator",
    "firmware",
    "firmware_checks",
    "link",
    "motor",
    "pin_trace",
    "pneunet",
    "programs",
    "protocol",
    "recorder",
    "recording",
    "run",
    "six_chamber",
]
