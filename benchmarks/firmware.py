"""The rigs' firmware on the simulated ATmega2560 (issue "The rigs' firmware").

    python benchmarks/firmware.py [--json] [--build DIR]

Builds firmware/ (make, into DIR or a temporary folder), then:
  motor_loop_cycles_max     worst-case CPU cycles of one 1 kHz control step of the motor
                            firmware (its two interrupts, entry to return, as simavr counts
                            them) over the runs of Figs. 4.5-4.9 (6000 steps each)
  motor_loop_budget_fraction  that / 16 000 (the cycles of one 1 ms period at 16 MHz;
                            target <= 0.25)
  motor_loop_cycles_median  the typical step
  pneunet_loop_cycles_max   the PneuNet's PID step over one 4 s experiment, and its
                            fraction of the 33.3 ms period (pneunet_loop_budget_fraction)
  flash_bytes, ram_bytes    per program, from avr-size: flash = .text + .data, RAM = .data
                            + .bss (static; the stack comes on top); ram_fraction of the
                            ATmega2560's 8 KiB (target <= 0.5)
  firmware_run_s, simulation_run_s  wall time of Fig. 4.6 on the emulated firmware (over the
                            pty) and, the baseline, in process (simulate_batch); their ratio
"""

from __future__ import annotations

import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from common import run

from articula.book.ch4.experiment import CurrentControlConfig, simulate_batch
from articula.book.ch4.rig import firmware_motor, run_on_rig
from articula.book.study import packaged
from articula.rigs.firmware import FirmwareRig
from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetPins, PneuNetRig
from articula.rigs.programs import steps
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.validation import load_toml, parse_model

FIRMWARE = Path(__file__).resolve().parents[1] / "firmware"
PROGRAMS = ("motor", "pneunet", "six_chamber")
FIGURES = ("fig4_5", "fig4_6", "fig4_7", "fig4_8", "fig4_9")
RAM = 8192  # [bytes] the ATmega2560's SRAM
MOTOR_PERIOD_CYCLES = 16_000
PNEUNET_PERIOD_CYCLES = 533_312  # 8333 ticks of Timer1 at 16 MHz / 64


def measure(build: str | None) -> dict[str, Any]:
    """The keys of the module's docstring."""
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(build or scratch)
        subprocess.run(["make", "-s", "-C", str(FIRMWARE), f"BUILD={folder}"], check=True)
        m: dict[str, Any] = {"flash_bytes": {}, "ram_bytes": {}, "ram_fraction": {}}
        for name in PROGRAMS:
            text, data, bss = _size(folder / f"{name}.elf")
            m["flash_bytes"][name] = text + data
            m["ram_bytes"][name] = data + bss
            m["ram_fraction"][name] = (data + bss) / RAM
        cycles, wall = [], {}
        for figure in FIGURES:
            config = _figure(figure)
            plant = firmware_motor(config)
            with FirmwareRig(folder / "motor.elf", plant) as rig, \
                    Link(rig.path, RigKind.MOTOR) as link, \
                    tempfile.TemporaryDirectory() as out:  # fmt: skip
                recorder = Recorder(Path(out), {}, [c.name for c in link.info.channels])
                start = time.perf_counter()
                run_on_rig(config, link, recorder)
                wall[figure] = time.perf_counter() - start
                cycles += rig.step_cycles[1:]  # the first reports the cycles before the run
        m["motor_loop_cycles_max"] = int(max(cycles))
        m["motor_loop_cycles_median"] = float(np.median(cycles))
        m["motor_loop_budget_fraction"] = m["motor_loop_cycles_max"] / MOTOR_PERIOD_CYCLES
        start = time.perf_counter()
        simulate_batch(_figure("fig4_6"), trials=1)
        m["simulation_run_s"] = time.perf_counter() - start
        m["firmware_run_s"] = wall["fig4_6"]
        m["firmware_vs_simulation"] = m["firmware_run_s"] / m["simulation_run_s"]
        with FirmwareRig(folder / "pneunet.elf", PneuNetPins()) as rig, Link(rig.path) as link:
            PneuNetRig(link, steps((30.0, 60.0), 2.0), 4.0, 0)(np.array([2.0, 1.5, 0.05]))
            m["pneunet_loop_cycles_max"] = int(max(rig.step_cycles[1:]))
        m["pneunet_loop_budget_fraction"] = m["pneunet_loop_cycles_max"] / PNEUNET_PERIOD_CYCLES
    return m


def _size(elf: Path) -> tuple[int, int, int]:
    """(.text, .data, .bss) bytes of an ELF, from avr-size."""
    line = subprocess.run(["avr-size", str(elf)], capture_output=True, text=True,
                          check=True).stdout.splitlines()[1]  # fmt: skip
    text, data, bss = map(int, line.split()[:3])
    return text, data, bss


def _figure(name: str) -> CurrentControlConfig:
    """A packaged chapter-4 figure config."""
    data = load_toml(packaged("ch4", f"{name}.toml"))
    data.pop("experiment")
    return parse_model(CurrentControlConfig, data, name)


def table(m: dict[str, Any]) -> tuple[str, list[str], list[list[str]]]:
    """One row per measure, against its target."""
    rows = [
        ["motor step, worst [cycles]", f"{m['motor_loop_cycles_max']}", ""],
        ["motor step, median [cycles]", f"{m['motor_loop_cycles_median']:.0f}", ""],
        ["motor step / 1 ms period", f"{m['motor_loop_budget_fraction']:.3f}", "<= 0.25"],
        ["PneuNet step / 33.3 ms period", f"{m['pneunet_loop_budget_fraction']:.4f}", ""],
    ]
    for name in PROGRAMS:
        rows.append([f"{name}: flash [bytes]", f"{m['flash_bytes'][name]}", "<= 262144"])
        rows.append([f"{name}: RAM [bytes] (of 8192)", f"{m['ram_bytes'][name]}", "<= 4096"])
    rows += [
        ["Fig. 4.6 on the firmware [s]", f"{m['firmware_run_s']:.2f}", ""],
        ["Fig. 4.6 in process [s] (baseline)", f"{m['simulation_run_s']:.3f}", ""],
        ["firmware / in process", f"{m['firmware_vs_simulation']:.0f}", ""],
    ]
    return "rig firmware on the simulated ATmega2560", ["measure", "value", "target"], rows


if __name__ == "__main__":
    build = {"type": str, "default": None, "help": "build folder (default: temporary)"}
    run(__doc__, measure, table, build=build)
