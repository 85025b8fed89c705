"""Chapter 2's experiment (pneunet.pid) on a PneuNet rig over serial (`articula rig run`).

The config is the one `articula run` takes (pneunet.pid); the rig runs its gain schedule
against its reference, one run from rest per trial (noise seed seed + i on an emulated rig),
and each sample goes to the recorder as it arrives. E (2.7) and M (2.5) are taken on the
sensor's angle: a rig has no other.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from articula.control.pid import GainSchedule
from articula.errors import ConfigError
from articula.experiments.pneunet import AngleReference, PneuNetPidConfig
from articula.plants.pneunet import PneuNetParams
from articula.rigs.link import Link
from articula.rigs.pneunet import encode_gains
from articula.rigs.programs import Program, Shape, steps
from articula.rigs.protocol import Info, Kind
from articula.rigs.recorder import Recorder
from articula.rigs.run import run_program
from articula.tuning.response import tracking_error, tuning_cost
from articula.validation import load_experiment_config

CHANNELS = ("trial", "theta_ref_deg", "theta_meas_deg", "pwm")  # the recorder's columns


def channels(info: Info) -> tuple[str, ...]:
    """The recorder's columns for the rig that `info` describes.

    Args:
        info: The rig's INFO.

    Returns:
        The trial, reference, measured angle and PWM columns.
    """
    return CHANNELS


def plant_config(path: Path | None) -> PneuNetParams:
    """The PneuNet an emulated rig has: the [plant] table of a pneunet.pid config (what
    `articula identify pneunet` writes as plant.toml).

    Args:
        path: A pneunet.pid config file (its `experiment` key is optional); None: the
            chapter's defaults.

    Returns:
        The actuator's constants (ConfigError naming the file and key where they do not read).
    """
    return load_experiment_config(path, PneuNetPidConfig).plant


def reference_program(reference: AngleReference, duration: float) -> Program:
    """The reference as the rig's program: a sinusoid, or steps sharing the run equally.

    Args:
        reference: The config's angle reference.
        duration: The run's length [s].

    Returns:
        The program the rig plays.
    """
    if reference.kind == "sinusoid":
        return Program(
            Shape.SINUSOID, (reference.offset_deg, reference.amplitude_deg, reference.frequency)
        )
    return steps(reference.levels_deg, duration / len(reference.levels_deg))


def run_on_rig(config: PneuNetPidConfig, link: Link, recorder: Recorder) -> dict[str, float]:
    """Every trial of `config` on the rig behind `link`.

    Args:
        config: The pneunet.pid config; its gain schedule and reference are sent to the rig.
        link: The line to a PneuNet rig.
        recorder: Takes every sample as it arrives, with its trial.

    Returns:
        E (2.7) quartiles [°] and the median M (2.5) over the trials.
    """
    c = config.controller
    if c.derivative_tau != 0.0 or c.pwm_bits != 8:
        raise ConfigError(
            "controller",
            "the rig's firmware runs the book's PID: unfiltered "
            "derivative (derivative_tau = 0), 8-bit PWM (pwm_bits = 8)",
        )
    points = np.array(c.points_deg) if c.schedule != "constant" else np.zeros(1)
    schedule = GainSchedule(c.schedule, np.array(c.gains), points)
    link.command(Kind.SET_GAINS, encode_gains(schedule))
    link.command(Kind.SET_REFERENCE, reference_program(config.reference, config.duration).encode())
    errors, costs = [], []
    for trial in range(config.trials):
        t, values = run_program(
            link,
            config.duration,
            config.seed + trial,
            lambda t, row, k=trial: recorder.add(t, np.r_[k, row]),
        )
        keep = t >= config.settle
        reference, measured = values[keep, 0], values[keep, 1]
        errors.append(float(tracking_error(reference, measured)))
        costs.append(float(tuning_cost(t[keep], reference, measured)))
    q1, median, q3 = np.percentile(errors, [25, 50, 75])
    return {
        "error_median_deg": float(median),
        "error_q1_deg": float(q1),
        "error_q3_deg": float(q3),
        "cost_median": float(np.median(costs)),
    }
