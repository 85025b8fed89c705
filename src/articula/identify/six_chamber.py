"""The six-chamber actuator's constants from recordings of its orientation sensor: the rig's
own actuation (fill a side, hold, vent, with its damping pulse) simulated with candidate
constants (plants.six_chamber_sim through loops.six_chamber.deactuate, as the emulated rig
runs it, its valve program computed from the same constants as the device computes its own),
the sensor's bending against the measured one.

Fitted: the silicone's youngs_modulus (the bending's stiffness and frequency), its damping, and
the valves' orifice_diameter (the fill and vent rates). Given: the discharge coefficient (only
its product with the orifice's area shows in the flow), the geometry and the supply pressure.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from articula.control.damping import DampingPolicy
from articula.errors import ConfigError
from articula.identify.fit import (
    Curve,
    Identification,
    fit_recordings,
    sample_period,
)
from articula.loops.six_chamber import deactuate, valve_program
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import SixChamberParams

CONSTANTS = ("youngs_modulus", "damping", "orifice_diameter")
GIVEN = ("discharge",)  # only discharge · orifice area shows in the flow
STEP = 1e-4  # [s] the plant's integration step (rigs/six_chamber.py's)
RECORD_EVERY = 10  # plant steps per kept sample
_DEFAULTS = SixChamberParams().model_dump()  # every constant a trial point does not set


@dataclass(frozen=True)
class SixChamberRecording:
    """One six-chamber recording, as the fit takes it.

    Attributes:
        dt: the sensor's sample period [s].
        bend: the measured bending (x, y) at each sample [deg], shape (n, 2).
        side: the side actuated [deg].
        gauge: the pressure it was filled to [Pa].
        hold: when it was vented [s].
        damping: the rig's damping pulse on venting.
    """

    dt: float
    bend: np.ndarray
    side: float
    gauge: float
    hold: float
    damping: DampingPolicy

    @classmethod
    def from_run(
        cls, columns: Mapping[str, np.ndarray], config: Mapping[str, Any], where: str
    ) -> SixChamberRecording:
        """A `rig record` folder's trace columns and config checked for the fit.

        Args:
            columns: column name -> values: t [s], bend_x, bend_y [deg].
            config: its config.toml (rig.record: the actuation and damping it ran).
            where: the recording, named in errors.

        Returns:
            The recording.
        """
        dt = sample_period(columns, ("bend_x", "bend_y"), 30, where, "six-chamber")
        settings = config.get("settings", {})
        reference = settings.get("reference", {})
        if config.get("rig") != "six-chamber" or reference.get("shape") != "actuation":
            raise ConfigError(
                where, "not a six-chamber `rig record` folder (no actuation in its config.toml)"
            )
        side, gauge, hold = (float(v) for v in reference["values"])
        damping = DampingPolicy(**settings.get("damping", {}))
        bend = np.column_stack([np.asarray(columns[c], dtype=float) for c in ("bend_x", "bend_y")])
        return cls(dt, bend, side, gauge, hold, damping)


def simulate(constants: Mapping[str, float], recording: SixChamberRecording) -> np.ndarray:
    """The actuator with `constants` run through the recording's actuation, noise-free.

    Args:
        constants: SixChamberParams' constants by name (SI); the rest at their defaults.
        recording: the recording whose actuation and damping it runs.

    Returns:
        The sensor's bending (x, y) at each of the recording's samples [deg], shape (n, 2).
    """
    # Built without validation: a trial point of the fit is checked by the bounds alone.
    p = SixChamberParams.model_construct(**(_DEFAULTS | dict(constants)))
    sensor = OrientationSensorParams(rate=1.0 / recording.dt, noise_deg=0.0)
    r = recording
    program = valve_program(p, r.side, r.gauge, r.hold, r.damping)
    n = r.bend.shape[0]
    after = n * r.dt - r.hold
    done = deactuate(p, sensor, program, r.side, r.hold, after, STEP, RECORD_EVERY,
                     np.random.default_rng(0))  # fmt: skip
    bend = np.degrees(done.sensor_bend[:n])
    if bend.shape[0] < n:  # the sensor's last sample can fall just past the run
        bend = np.vstack([bend, np.repeat(bend[-1:], n - bend.shape[0], axis=0)])
    return bend


def identify_six_chamber(
    recordings: Sequence[SixChamberRecording], start: SixChamberParams | None = None
) -> Identification:
    """Fit youngs_modulus, damping and orifice_diameter to every recording but the last;
    validate on the last (each transient settles within its recording: a last quarter would
    hold only the sensor's noise).

    Args:
        recordings: `rig record` runs of the actuation program, from rest; two or more.
        start: where the fit starts, and the constants it takes as given; None: the defaults.

    Returns:
        The identification; its plant, a softarm.damping config's [actuator] table.
    """
    start = start or SixChamberParams()

    def predict(constants: dict[str, float], k: int) -> dict[str, np.ndarray]:
        """The model's bending for recording k."""
        bend = simulate(constants, recordings[k])
        return {"bend_x": bend[:, 0], "bend_y": bend[:, 1]}

    begin = {name: getattr(start, name) for name in (*CONSTANTS, *GIVEN)}
    measured = [{"bend_x": r.bend[:, 0], "bend_y": r.bend[:, 1]} for r in recordings]
    fit, validation, begin = fit_recordings(predict, measured, begin, CONSTANTS, hold_out_last=True)
    fit = dataclasses.replace(fit, unidentifiable=(*fit.unidentifiable, *GIVEN))
    constants = begin | fit.values
    plant = {"experiment": "softarm.damping", "actuator": start.model_dump() | constants}
    held = recordings[-1]  # the figure shows the prediction of the held-out recording
    t = np.arange(held.bend.shape[0]) * held.dt
    model = simulate(constants, held)
    curves = tuple(
        Curve(f"bend {axis} [deg]", t, held.bend[:, k], model[:, k], 0.0)
        for k, axis in enumerate("xy")
    )
    return Identification(fit, validation, begin, plant, curves)
