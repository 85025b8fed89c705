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

motor_loop_cycles_max takes every path: the five figures (constant, step and sinusoidal
references, saturation) and a run with command bursts; a step is its two interrupts (the
control tick, the ADC's sample) and its main-loop part, less the interrupts that came
meanwhile. motor_step_latency_cycles_max: from the sample's interrupt to the end of its
step, everything included (the main loop may be sending a frame when the sample comes).

Safety (issue 27), on the emulated board with its pins read from the harness's trace
(articula.rigs.firmware_checks):
  stop_trials, stop_failures  STOPs at random phases of the control period (300 motor, 100
                            PneuNet, 100 six-chamber), and those after which an output was
                            active more than one period after the STOP's ACK;
                            stop_phase_bins (of 10) the STOPs fell in, per rig;
                            stop_ack_to_safe_ms_max (negative: off before the ACK went out)
  host_loss_trials, host_loss_latency_ms_max  runs whose host went silent (host_timeout_ms
                            100, 250, 500 in turn), and the longest from its last frame to
                            every output off; host_loss_over_timeout_ms_max: that beyond
                            each run's timeout (target: at most one period)
  rx_overruns               bytes lost by the firmware's USART (the harness models its
                            2-byte buffer) over runs at 1 Mbaud with command bursts mid-run,
                            its STOP included (motor, PneuNet, six-chamber)
  watchdog_reset_ok         on each rig a hung main loop put the outputs off within the
                            watchdog's 32.0 ms, reset the board, and the host raised
                            DeviceResetError naming the watchdog; watchdog_outputs_off_ms_max

No byte dropped (issue 47), per rig:
  burst_after_stop_lost_bytes  bytes lost over the burst trials: a STOP or a START with three
                            STATUS behind it in one write, a run's own end (DONE) inside the
                            host's bursts (BURST_TRIALS of each; burst_trials counts them,
                            burst_done_covered the DONEs that fell inside a burst)
  max_interrupts_off_cycles {"measured": the longest section with interrupts off the harness
                            traced over all of the rig's trials above, "static": the longest
                            path of any such section in the ELF (tools/interrupts_off.py)};
                            target <= 160, a byte at 1 Mbaud
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from common import run

from articula.book.study import packaged
from articula.experiments.motor import CurrentControlConfig, simulate_batch
from articula.experiments.motor_on_rig import firmware_motor, run_on_rig
from articula.rigs.firmware import FirmwareRig
from articula.rigs.firmware_checks import (
    burst_trial,
    host_loss_trial,
    short_run,
    stop_trial,
    traffic_trial,
    watchdog_trial,
)
from articula.rigs.link import Link
from articula.rigs.pin_trace import PinTrace
from articula.rigs.pneunet import PneuNetPins, PneuNetRig
from articula.rigs.programs import steps
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.rigs.six_chamber import SixChamberPins
from articula.validation import load_toml, parse_model

FIRMWARE = Path(__file__).resolve().parents[1] / "firmware"
PROGRAMS = ("motor", "pneunet", "six_chamber")
FIGURES = ("fig4_5", "fig4_6", "fig4_7", "fig4_8", "fig4_9")
RAM = 8192  # [bytes] the ATmega2560's SRAM
MOTOR_PERIOD_CYCLES = 16_000
PNEUNET_PERIOD_CYCLES = 533_312  # 8333 ticks of Timer1 at 16 MHz / 64
STOPS = {"motor": 300, "pneunet": 100, "six_chamber": 100}
HOST_LOSSES = {"motor": 10, "pneunet": 5, "six_chamber": 5}
HOST_TIMEOUTS_MS = (100, 250, 500)
BURSTS = {"motor": 100, "pneunet": 30, "six_chamber": 30}
BURST_TRIALS = {"stop": 100, "start": 50, "done": 50}  # per rig
TOOLS = Path(__file__).resolve().parents[1] / "tools"


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
        cycles, latency, wall = [], [], {}
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
                latency += rig.step_latency[1:]
        m.update(safety(folder, cycles, latency))
        m["motor_loop_cycles_max"] = int(max(cycles))
        m["motor_step_latency_cycles_max"] = int(max(latency))
        m["motor_step_latency_fraction"] = m["motor_step_latency_cycles_max"] / MOTOR_PERIOD_CYCLES
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


def safety(folder: Path, cycles: list[int], latency: list[int]) -> dict[str, Any]:
    """The safety keys of the module's docstring; the motor's steps under command bursts
    are added to `cycles` and `latency`."""
    plants = {"motor": lambda: firmware_motor(CurrentControlConfig()), "pneunet": PneuNetPins,
              "six_chamber": SixChamberPins}  # fmt: skip
    rng = np.random.default_rng(27)
    m: dict[str, Any] = {"stop_trials": 0, "stop_failures": 0, "stop_phase_bins": {},
                         "stop_ack_to_safe_ms_max": -np.inf, "host_loss_trials": 0,
                         "host_loss_latency_ms_max": 0.0, "host_loss_over_timeout_ms_max": 0.0,
                         "rx_overruns": 0, "watchdog_reset_ok": True,
                         "watchdog_outputs_off_ms_max": 0.0, "burst_after_stop_lost_bytes": {},
                         "burst_trials": {}, "burst_done_covered": {},
                         "max_interrupts_off_cycles": {}}  # fmt: skip
    static = _static_bounds(folder)
    for name, make in plants.items():
        with tempfile.TemporaryDirectory() as scratch:
            path = Path(scratch) / "trace"
            with FirmwareRig(folder / f"{name}.elf", make(), trace=path) as rig, \
                    Link(rig.path) as link:  # fmt: skip
                trace = PinTrace(path)
                stops = [stop_trial(rig, trace, link, rng) for _ in range(STOPS[name])]
                m["stop_trials"] += len(stops)
                m["stop_failures"] += sum(t.failed for t in stops)
                m["stop_phase_bins"][name] = len({int(10 * t.phase) for t in stops})
                worst = max(t.ack_to_safe_s for t in stops) * 1e3
                m["stop_ack_to_safe_ms_max"] = max(m["stop_ack_to_safe_ms_max"], worst)
                for k in range(HOST_LOSSES[name]):
                    timeout = HOST_TIMEOUTS_MS[k % len(HOST_TIMEOUTS_MS)]
                    loss = host_loss_trial(rig, trace, link, timeout)
                    m["host_loss_trials"] += 1
                    ms = loss.latency_s * 1e3 if loss.said_why else np.inf
                    m["host_loss_latency_ms_max"] = max(m["host_loss_latency_ms_max"], ms)
                    over = max(m["host_loss_over_timeout_ms_max"], ms - timeout)
                    m["host_loss_over_timeout_ms_max"] = over
                m["rx_overruns"] += traffic_trial(rig, trace, link, BURSTS[name])
                run_s = short_run(link)
                events = [e for e, count in BURST_TRIALS.items() for _ in range(count)]
                bursts = [burst_trial(trace, link, event, run_s) for event in events]
                m["burst_after_stop_lost_bytes"][name] = sum(t.lost_bytes for t in bursts)
                m["burst_trials"][name] = len(bursts)
                m["burst_done_covered"][name] = sum(t.covered for t in bursts if t.event == "done")
                if name == "motor":
                    cycles += rig.step_cycles[1:]
                    latency += rig.step_latency[1:]
                ok, off_s = watchdog_trial(rig, trace, link)
                m["watchdog_reset_ok"] &= ok
                m["watchdog_outputs_off_ms_max"] = max(m["watchdog_outputs_off_ms_max"],
                                                       off_s * 1e3)  # fmt: skip
                measured = trace.update().interrupts_off[-1].cycles
                m["max_interrupts_off_cycles"][name] = {"measured": measured,
                                                        "static": static[name]}  # fmt: skip
    return m


def _static_bounds(folder: Path) -> dict[str, int | None]:
    """Per program, the longest interrupts-off section of its ELF (tools/interrupts_off.py)
    [CPU cycles]; None for one without a bound."""
    elves = [str(folder / f"{name}.elf") for name in PROGRAMS]
    proc = subprocess.run([sys.executable, str(TOOLS / "interrupts_off.py"), "--json", *elves],
                          capture_output=True, text=True)  # fmt: skip
    return {name: r["max_cycles"] for name, r in json.loads(proc.stdout).items()}


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
        ["motor step latency, worst [cycles]", f"{m['motor_step_latency_cycles_max']}", ""],
        ["PneuNet step / 33.3 ms period", f"{m['pneunet_loop_budget_fraction']:.4f}", ""],
        ["STOPs at random phases", f"{m['stop_trials']}", ">= 500"],
        ["  outputs on > 1 period after the ACK", f"{m['stop_failures']}", "0"],
        ["  ACK to outputs off, worst [ms]", f"{m['stop_ack_to_safe_ms_max']:.3f}", ""],
        ["silent hosts", f"{m['host_loss_trials']}", ">= 20"],
        ["  last frame to outputs off, worst [ms]", f"{m['host_loss_latency_ms_max']:.2f}", ""],
        [
            "  beyond host_timeout_ms, worst [ms]",
            f"{m['host_loss_over_timeout_ms_max']:.2f}",
            "<= 1 period",
        ],
        ["bytes lost at 1 Mbaud, bursts mid-run", f"{m['rx_overruns']}", "0"],
        ["hung main loop: watchdog reset reported", f"{m['watchdog_reset_ok']}", "True"],
        ["  hang to outputs off, worst [ms]", f"{m['watchdog_outputs_off_ms_max']:.2f}", "<= 32.0"],
    ]
    for name in PROGRAMS:
        off = m["max_interrupts_off_cycles"][name]
        rows.append([f"{name}: bytes lost behind STOP/START/DONE ({m['burst_trials'][name]} "
                     f"trials, {m['burst_done_covered'][name]} DONEs in a burst)",
                     f"{m['burst_after_stop_lost_bytes'][name]}", "0"])  # fmt: skip
        rows.append([f"{name}: interrupts off, longest: measured / static [cycles]",
                     f"{off['measured']} / {off['static']}", "<= 160"])  # fmt: skip
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
