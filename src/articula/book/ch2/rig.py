"""Chapter 2 on a PneuNet rig over serial: its experiment (`articula rig run`) and its
tuners (`articula rig tune`).

The config is the one `articula run` takes (pneunet.pid); the rig runs its gain schedule
against its reference, one run from rest per trial (noise seed seed + i on an emulated rig),
and each sample goes to the recorder as it arrives. E (2.7) and M (2.5) are taken on the
sensor's angle: a rig has no other.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from articula.book.ch2.study import ZN_LADDER, ZN_SEED_OFFSET
from articula.book.ch2.tuning import TuningConfig, auto_run, auto_seed, manual_seed
from articula.control.pid import GainSchedule
from articula.errors import ConfigError
from articula.experiments.pneunet import AngleReference, PneuNetPidConfig
from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetRig, encode_gains
from articula.rigs.programs import Program, Shape, steps
from articula.rigs.protocol import Info, Kind
from articula.rigs.recorder import Recorder
from articula.rigs.run import run_program
from articula.tuning.manual import (
    GainExperiment,
    ManualSettings,
    manual_tuning,
    ultimate_gain,
    ziegler_nichols,
)
from articula.tuning.response import Response, tracking_error, tuning_cost

CHANNELS = ("trial", "theta_ref_deg", "theta_meas_deg", "pwm")  # the recorder's columns


def channels(info: Info) -> tuple[str, ...]:
    """The recorder's columns for the rig that `info` describes."""
    return CHANNELS


def reference_program(reference: AngleReference, duration: float) -> Program:
    """The reference as the rig's program: a sinusoid, or steps sharing the run equally."""
    if reference.kind == "sinusoid":
        return Program(
            Shape.SINUSOID, (reference.offset_deg, reference.amplitude_deg, reference.frequency)
        )
    return steps(reference.levels_deg, duration / len(reference.levels_deg))


def run_on_rig(config: PneuNetPidConfig, link: Link, recorder: Recorder) -> dict[str, float]:
    """Every trial of `config` on the rig behind `link`; returns the metrics."""
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


TUNERS = ("descent", "manual", "ziegler-nichols")


def tune_on_rig(
    tuning: TuningConfig,
    link: Link,
    method: str,
    levels: tuple[float, ...],
    index: int = 0,
    on_experiment: Callable[[], None] | None = None,
) -> dict[str, Any]:
    """Chapter 2's tuners, unchanged, with the rig behind `link` as their experiment: the
    coordinate descent (Algorithm 1) on steps through `levels`, the scripted manual procedure
    or Ziegler-Nichols' ultimate gain on a step to levels[0] [°]; the noise seeds are the
    in-process runs' (an emulated rig then gives their numbers). Returns the result as JSON."""

    def rig(program_levels: tuple[float, ...], hold: float, seed: int) -> GainExperiment:
        on_rig = PneuNetRig(link, steps(program_levels, hold), len(program_levels) * hold, seed)

        def experiment(k: np.ndarray) -> Response:
            if on_experiment is not None:
                on_experiment()
            return on_rig(k)

        return experiment

    m, level = tuning.manual, levels[0]
    if method == "descent":
        run = auto_run(
            tuning, levels, index, rig(levels, tuning.auto.hold, auto_seed(tuning, index))
        ).result
        return {
            "method": method,
            "levels_deg": list(levels),
            "gains": run.k.tolist(),
            "cost": run.cost,
            "experiments": run.evaluations,
            "sweeps": len(run.history) - 1,
        }
    if method == "manual":
        experiment = rig((level,), m.hold, manual_seed(tuning, level))
        found = manual_tuning(experiment, ManualSettings(band=m.band, tolerance=m.tolerance))
        return {
            "method": method,
            "levels_deg": [level],
            "gains": found.gains.tolist(),
            "experiments": len(found.trials),
            "within_tolerance": found.within_tolerance,
        }
    if method != "ziegler-nichols":
        raise ConfigError("--method", f"unknown tuner {method!r}; choose one of {TUNERS}")
    ku, tu, trials = ultimate_gain(
        rig((level,), m.hold, m.seed + ZN_SEED_OFFSET), ZN_LADDER, m.band
    )
    return {
        "method": method,
        "levels_deg": [level],
        "ku": ku,
        "tu_s": tu,
        "gains": ziegler_nichols(ku, tu, "PID").tolist(),
        "gains_pi": ziegler_nichols(ku, tu, "PI").tolist(),
        "experiments": len(trials),
    }
