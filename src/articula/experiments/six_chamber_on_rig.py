"""Chapter 3's experiment on the six-chamber rig over serial (`articula rig run`).

The config is the one `articula run` takes (softarm.damping); the rig fills its side, holds,
vents and damps by the policy, and streams its orientation sensor. The metrics are those the
book measured, on the sensor: peak, overshoot, settling and the angle at deactuation (the
true angle and the chamber pressures are the simulation's alone).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from articula.control.chamber_allocation import bend_direction
from articula.experiments.six_chamber import DeactuationConfig, oscillation_metrics
from articula.plants.six_chamber import SixChamberParams
from articula.rigs.link import Link
from articula.rigs.programs import Program, Shape
from articula.rigs.protocol import Info, Kind
from articula.rigs.recorder import Recorder
from articula.rigs.run import run_program
from articula.rigs.six_chamber import encode_damping
from articula.validation import load_experiment_config

CHANNELS = ("bend_x_deg", "bend_y_deg")  # the recorder's columns


def plant_config(path: Path | None) -> SixChamberParams:
    """The actuator an emulated rig has: the [actuator] table of a softarm.damping config
    (what `articula identify six-chamber` writes as plant.toml).

    Args:
        path: A softarm.damping config file (its `experiment` key is optional); None: the
            chapter's defaults.

    Returns:
        The actuator's constants (ConfigError naming the file and key where they do not read).
    """
    return load_experiment_config(path, DeactuationConfig).actuator


def channels(info: Info) -> tuple[str, ...]:
    """The recorder's columns for the rig that `info` describes.

    Args:
        info: The rig's INFO.

    Returns:
        The sensor's two bend angles.
    """
    return CHANNELS


def run_on_rig(config: DeactuationConfig, link: Link, recorder: Recorder) -> dict[str, float]:
    """One actuate-hold-deactuate run of `config` on the rig behind `link`.

    Args:
        config: The softarm.damping config; its actuation and damping are sent to the rig.
        link: The line to a six-chamber rig.
        recorder: Takes every sample as it arrives.

    Returns:
        Peak [°], overshoot [%], settling [s] and the angle at deactuation [°].
    """
    actuation = Program(Shape.ACTUATION, (config.side_deg, config.gauge, config.hold))
    link.command(Kind.SET_REFERENCE, actuation.encode())
    link.command(Kind.SET_DAMPING, encode_damping(config.damping))
    t, bend = run_program(link, config.hold + config.after, config.seed, recorder.add)
    angle = np.radians(bend) @ bend_direction(config.side_deg)
    m = oscillation_metrics(t, angle, config.hold, np.radians(config.band_deg))
    return {
        "peak_deg": float(np.degrees(m["peak"])),
        "overshoot_pct": 100 * m["overshoot"],
        "settling_s": round(m["settling"], 6),
        "deactuation_angle_deg": float(np.degrees(m["start"])),
    }
