"""`articula rig identify`: an excitation designed for identification run on the rig, each part
recorded as a run folder, then fitted (identify/).

The motor's excitation is three current programs the rig's own loop tracks, within its safe
amplitudes (SAFE_CURRENT): a constant current with a slow sinusoid that spins the shaft up
until the driver's voltage saturates (K and b, from the speed the back-emf allows), a slow
sinusoid about zero (J, from the speed swing) and a fast one (L and R, from the current's
response). The speed loop's gains are 0, so a load motor on the shaft is never driven.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from articula.errors import ConfigError
from articula.experiments.motor import CurrentControlConfig, CurrentReference
from articula.experiments.motor_on_rig import channels, run_on_rig
from articula.identify.folders import DEFAULT_WINDOW, fit_and_write
from articula.rigs.link import Link
from articula.rigs.protocol import RigKind
from articula.rigs.recorder import Recorder
from articula.runs.folders import check_out, claimed
from articula.runs.registry import config_to_dict, experiment

SAFE_CURRENT = 0.8  # [A] the largest current the excitation asks for (ACS712-5A: ±5 A)
# (constant [A], amplitude [A], frequency [Hz], duration [s]) of each part.
MOTOR_EXCITATION = ((0.4, 0.4, 2.0, 20.0), (0.0, 0.7, 0.2, 20.0), (0.0, 0.5, 40.0, 5.0))


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


def identify_on_rig(
    port: str,
    rig: str,
    out_dir: Path,
    seed: int = 0,
    window: int = DEFAULT_WINDOW,
    force: bool = False,
    progress=None,
) -> dict[str, Any]:
    """Run the excitation on the rig, record each part into out_dir/excitation_<k>, fit.

    Args:
        port: the rig's serial port.
        rig: the rig's name (motor).
        out_dir: the identification's folder.
        seed: the noise seed of an emulated rig.
        window: the encoder's window [samples].
        force: write into a folder holding other files.
        progress: called with no arguments after each part; None: silent.

    Returns:
        identification.json's content, with the excitation it ran.
    """
    if rig != "motor":
        raise ConfigError("RIG", f"rig identify runs on the motor rig so far (got {rig!r})")
    check_out(out_dir, "identification", force)
    motor_current = experiment("motor.current")
    folders = []
    with Link(port, RigKind.MOTOR) as link, claimed(out_dir, "identification", force):
        for k, config in enumerate(excitation_configs(seed), start=1):
            folder = out_dir / f"excitation_{k}"
            recorder = Recorder(folder, config_to_dict(motor_current, config), channels(link.info))
            recorder.capture(lambda c=config, r=recorder: run_on_rig(c, link, r), link.stats)
            folders.append(folder)
            if progress is not None:
                progress()
        excitation = [
            {"current_A": c, "amplitude_A": a, "frequency_Hz": f, "duration_s": d}
            for c, a, f, d in MOTOR_EXCITATION
        ]
        extra = {"excitation": excitation, "safe_current_A": SAFE_CURRENT}
        return fit_and_write(rig, folders, out_dir, window, extra)
