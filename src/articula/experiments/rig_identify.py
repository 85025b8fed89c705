"""`articula rig identify`: an excitation designed for identification run on the rig on the
port (whichever it reports), each part recorded as a run folder, then fitted (identify/).

The motor's excitation is three current programs the rig's own loop tracks, within its safe
amplitudes (SAFE_CURRENT): a constant current with a 2 Hz sinusoid that spins the shaft up
until the driver's voltage saturates (K and b, from the speed the back-emf allows), a slow
sinusoid about zero (J, from the speed swing) and a fast one (L and R, from the current's
response); the speed loop's gains are 0, so a load motor on the shaft is never driven. The
PneuNet's is four open-loop steps of the valve's PWM count from rest (SET_OUTPUT), at most
SAFE_PWM: the angles they settle at give the pressure-to-angle map, their rise the chamber's
lag and the bending's frequency and damping. The six-chamber's is four actuations (a side
filled to the supply, held 0.6-1 s, vented, no damping pulse), the last held out.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from pathlib import Path
from typing import Any

from articula.control.damping import DampingPolicy
from articula.experiments.motor import CurrentControlConfig, CurrentReference
from articula.experiments.motor_on_rig import channels, run_on_rig
from articula.identify.folders import DEFAULT_WINDOW, fit_and_write
from articula.plants.six_chamber import SixChamberParams
from articula.rigs.link import Link
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import Kind, RigKind
from articula.rigs.recorder import Recorder
from articula.rigs.recording import RIGS, recording_config
from articula.rigs.run import run_program
from articula.rigs.six_chamber import encode_damping
from articula.runs.folders import check_out, claimed
from articula.runs.registry import config_to_dict, experiment

SAFE_CURRENT = 0.8  # [A] the largest current the motor's excitation asks for (ACS712-5A: ±5 A)
# (constant [A], amplitude [A], frequency [Hz], duration [s]) of each part.
MOTOR_EXCITATION = ((0.4, 0.4, 2.0, 20.0), (0.0, 0.7, 0.2, 20.0), (0.0, 0.5, 40.0, 5.0))
SAFE_PWM = 220  # the largest valve count the PneuNet's excitation holds (of 255: 86 % duty)
PNEUNET_EXCITATION = ((60, 5.0), (100, 5.0), (150, 5.0), (220, 5.0))  # (count, duration [s])
# The six-chamber's: (side [deg], pressure [share of the book's 100 kPa supply], hold [s],
# duration [s]); the last is held out for validation. At the supply and on a chamber's side
# (a multiple of 60°): all the firmware fills; the rig refuses more than its supply.
SIX_CHAMBER_EXCITATION = (
    (0.0, 1.0, 1.0, 2.5),
    (120.0, 1.0, 0.6, 2.0),
    (240.0, 1.0, 0.8, 2.3),
    (60.0, 1.0, 1.0, 2.5),
)


def excitation_configs(seed: int) -> list[CurrentControlConfig]:
    """The motor's excitation as motor.current configs (their gains and references are sent).

    Args:
        seed: the noise seed of an emulated rig (the k-th part takes seed + k).

    Returns:
        One config per part.
    """
    configs = []
    for k, (current, amplitude, hertz, duration) in enumerate(MOTOR_EXCITATION):
        reference = CurrentReference(
            current=current, amplitude=amplitude, frequency=2 * math.pi * hertz, speed=0.0
        )
        configs.append(
            CurrentControlConfig(
                rig="single",
                seed=seed + k,
                duration=duration,
                settle=0.0,
                reference=reference,
                speed_controller={"kp": 0.0, "ki": 0.0},
            )
        )
    return configs


def _motor_parts(link: Link, seed: int) -> list[Callable[[Path], None]]:
    """The motor's parts, each recording one run into a folder."""
    motor_current = experiment("motor.current")

    def part(config: CurrentControlConfig) -> Callable[[Path], None]:
        def record(folder: Path) -> None:
            recorder = Recorder(folder, config_to_dict(motor_current, config), channels(link.info))
            recorder.capture(lambda: run_on_rig(config, link, recorder), link.stats)

        return record

    return [part(config) for config in excitation_configs(seed)]


def _pneunet_parts(link: Link, seed: int) -> list[Callable[[Path], None]]:
    """The PneuNet's parts: a count held open-loop from rest, recorded as `rig record` does."""

    def part(count: int, duration: float, k: int) -> Callable[[Path], None]:
        def record(folder: Path) -> None:
            link.command(Kind.SET_OUTPUT, struct.pack("<Bf", 0, float(count)))
            _record(link, folder, duration, seed + k)

        return record

    return [part(c, d, k) for k, (c, d) in enumerate(PNEUNET_EXCITATION)]


def _six_chamber_parts(link: Link, seed: int) -> list[Callable[[Path], None]]:
    """The six-chamber's parts: a side filled, held and vented (no damping pulse), recorded
    as `rig record` does."""
    supply = SixChamberParams().supply  # the book's pump; the rig refuses more than its own

    def part(side: float, share: float, hold: float, duration: float, k: int):
        def record(folder: Path) -> None:
            program = Program(Shape.ACTUATION, (side, share * supply, hold))
            link.command(Kind.SET_REFERENCE, program.encode())
            link.command(Kind.SET_DAMPING, encode_damping(DampingPolicy()))
            _record(link, folder, duration, seed + k)

        return record

    return [part(*p, k) for k, p in enumerate(SIX_CHAMBER_EXCITATION)]


def _record(link: Link, folder: Path, duration: float, seed: int) -> None:
    """A `rig record` of what the rig holds now into `folder`."""
    recorder = Recorder(folder, recording_config(link, duration, seed),
                        [c.name for c in link.info.channels])  # fmt: skip

    def run() -> dict[str, float]:
        run_program(link, duration, seed, recorder.add)
        return {}  # a recording has no metrics

    recorder.capture(run, link.stats)


def excitation_summary(rig: str) -> dict[str, Any]:
    """What identification.json states of the excitation a rig ran.

    Args:
        rig: the rig's name (motor, pneunet or six-chamber).

    Returns:
        The parts and the safe amplitude they keep.
    """
    if rig == "motor":
        parts = [
            {"current_A": c, "amplitude_A": a, "frequency_Hz": f, "duration_s": d}
            for c, a, f, d in MOTOR_EXCITATION
        ]
        return {"excitation": parts, "safe_current_A": SAFE_CURRENT}
    if rig == "pneunet":
        parts = [{"pwm_count": c, "duration_s": d} for c, d in PNEUNET_EXCITATION]
        return {"excitation": parts, "safe_pwm_count": SAFE_PWM}
    parts = [
        {"side_deg": a, "supply_fraction": f, "hold_s": h, "duration_s": d}
        for a, f, h, d in SIX_CHAMBER_EXCITATION
    ]
    return {"excitation": parts, "held_out": "the last part"}


def identify_on_rig(
    port: str,
    out_dir: Path,
    seed: int = 0,
    window: int = DEFAULT_WINDOW,
    force: bool = False,
    progress: Callable[[], None] | None = None,
) -> dict[str, Any]:
    """Run the excitation on the rig, record each part into out_dir/excitation_<k>, fit.

    Args:
        port: the rig's serial port (any of the three rigs).
        out_dir: the identification's folder.
        seed: the noise seed of an emulated rig.
        window: the motor encoder's window [samples].
        force: write into a folder holding other files.
        progress: called with no arguments after each part; None: silent.

    Returns:
        identification.json's content, with the excitation it ran.
    """
    check_out(out_dir, "identification", force)
    with Link(port) as link:
        rig = {kind: word for word, kind in RIGS.items()}[link.info.rig]
        makers = {
            RigKind.MOTOR: _motor_parts,
            RigKind.PNEUNET: _pneunet_parts,
            RigKind.SIX_CHAMBER: _six_chamber_parts,
        }
        folders = []
        with claimed(out_dir, "identification", force):
            for k, record in enumerate(makers[link.info.rig](link, seed), start=1):
                folders.append(out_dir / f"excitation_{k}")
                record(folders[-1])
                if progress is not None:
                    progress()
            return fit_and_write(rig, folders, out_dir, window, excitation_summary(rig))
