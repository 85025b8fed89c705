"""Chapter 2 experiment: a PID of the family (2.2)-(2.4) on the simulated PneuNet, many trials.

The controller works in degrees because the book's gains are per degree; its output is the
8-bit PWM value (0-255) the Arduino writes, so K_p is in counts/°, K_i in counts/(°·s) and
K_d in counts·s/°. Everything else is SI inside and degrees at the interface.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from articula.control.pid import PID, GainSchedule
from articula.loops.pneunet_pid import ClosedLoopTrace, run_closed_loop
from articula.plants.pneunet import PneuNetParams
from articula.runs.registry import Experiment, Progress, Result
from articula.tuning.response import tracking_error, tuning_cost
from articula.validation import NonNegative, Positive, Seed, StrictModel, field_error

Angle = Annotated[float, Field(ge=0, le=90, allow_inf_nan=False)]  # [°], the book's range
GainRow = Annotated[list[NonNegative], Field(min_length=3, max_length=3)]
MAX_STEPS = 1_000_000
MAX_TRIALS = 10_000
MAX_SAMPLES = 20_000_000  # trials × steps: three float64 channels of this size are ~0.5 GB


class AngleReference(StrictModel):
    """θ_r(t) in degrees: a sinusoid from rest, or steps held for equal times.

    Attributes:
        kind: "sinusoid", θ_r = offset − amplitude·cos(2πft), which starts at rest, or
            "steps", the levels in order.
        offset_deg: mean of the sinusoid [°].
        amplitude_deg: amplitude of the sinusoid [°]; offset ± amplitude must lie in 0-90°.
        frequency: frequency f of the sinusoid, as in Table 2.3 [Hz].
        levels_deg: the step levels, in order, each held for an equal share of the run [°].
    """

    kind: Literal["sinusoid", "steps"] = "sinusoid"
    offset_deg: Angle = 45.0
    amplitude_deg: Angle = 45.0
    frequency: NonNegative = 0.05
    levels_deg: Annotated[list[Angle], Field(min_length=1)] = Field(  # steps, in order
        default_factory=lambda: [90.0]
    )

    @model_validator(mode="after")
    def _inside_range(self) -> AngleReference:
        lo, hi = self.offset_deg - self.amplitude_deg, self.offset_deg + self.amplitude_deg
        if self.kind == "sinusoid" and (lo < 0 or hi > 90):
            raise field_error(
                "amplitude_deg",
                f"the sinusoid spans {lo:g}-{hi:g}°, outside the book's 0-90°; "
                "lower amplitude_deg or move offset_deg",
            )
        return self


class ControllerConfig(StrictModel):
    """Gain schedule of Eq. (2.4), PWM output range and optional derivative filter.

    Attributes:
        name: a label, e.g. "fuzzy-auto"; reported, not interpreted.
        schedule: how the gains vary with θ_r, Eq. (2.4): "constant" (ordinary PID),
            "piecewise" or "fuzzy".
        gains: rows (K_p, K_i, K_d), one per point of points_deg (one row if constant), in
            counts/°, counts/(°·s) and counts·s/°.
        points_deg: representative points of θ_r, increasing (Sect. 2.4.2.1) [°]; ignored
            by a constant schedule.
        pwm_bits: PWM resolution [bits]: the output is clipped to 0 … 2^pwm_bits − 1
            counts (8: analogWrite's 0-255).
        derivative_tau: time constant of a first-order filter on the error's derivative [s];
            0: unfiltered, as in the book.
    """

    name: str = "ordinary"
    schedule: Literal["constant", "piecewise", "fuzzy"] = "constant"
    gains: Annotated[list[GainRow], Field(min_length=1)] = Field(  # rows [K_p, K_i, K_d]
        default_factory=lambda: [[1.0, 1.0, 0.0]]
    )
    points_deg: list[Angle] = Field(  # representative points (Sect. 2.4.2.1)
        default_factory=lambda: [15.0, 45.0, 75.0]
    )
    pwm_bits: Annotated[int, Field(ge=1, le=16)] = 8
    derivative_tau: NonNegative = 0.0

    @model_validator(mode="after")
    def _rows_match(self) -> ControllerConfig:
        rows = len(self.gains)
        if self.schedule == "constant" and rows != 1:
            raise field_error("gains", f"a constant schedule takes one row of gains (got {rows})")
        if self.schedule != "constant" and rows != len(self.points_deg):
            raise field_error(
                "gains",
                f"{self.schedule} needs one row of gains per point of points_deg "
                f"({len(self.points_deg)}), got {rows}",
            )
        if self.schedule != "constant" and any(
            b <= a for a, b in zip(self.points_deg, self.points_deg[1:], strict=False)
        ):
            raise field_error("points_deg", f"must increase (got {self.points_deg})")
        return self

    def build(self, trials: int) -> PID:
        """The PID this config describes, for `trials` parallel actuators.

        Args:
            trials: number of actuators controlled at once (the batch size).

        Returns:
            The PID, from the error [°] to the PWM count, its output clipped to the PWM range.
        """
        schedule = GainSchedule(self.schedule, np.array(self.gains), np.array(self.points_deg))
        return PID(schedule, (0.0, 2.0**self.pwm_bits - 1), self.derivative_tau, trials)


class PneuNetPidConfig(StrictModel):
    """`trials` runs of one controller on the PneuNet, each with its own noise seed.

    Attributes:
        seed: seed of trial 0; trial i draws its sensor noise and actuator variation from
            seed + i.
        trials: number of trials (the book runs 25).
        duration: length of each trial [s].
        settle: time before E is taken [s]; 0: every sample, as Eq. (2.7).
        reference: the reference θ_r(t).
        controller: the PID and its gain schedule.
        plant: the simulated PneuNet's constants.
    """

    seed: Seed = 0
    trials: Annotated[int, Field(ge=1, le=MAX_TRIALS)] = 25
    duration: Positive = 40.0
    settle: NonNegative = 0.0
    reference: AngleReference = AngleReference()
    controller: ControllerConfig = ControllerConfig()
    plant: PneuNetParams = PneuNetParams()

    @model_validator(mode="after")
    def _check_times(self) -> PneuNetPidConfig:
        steps = self.duration / self.plant.pwm_period
        if steps > MAX_STEPS:
            raise field_error(
                "duration", f"duration/pwm_period is over {MAX_STEPS} steps; shorten duration"
            )
        if steps * self.trials > MAX_SAMPLES:
            raise field_error(
                "trials",
                f"trials × steps is over {MAX_SAMPLES}; run fewer trials per config (a sweep "
                "over seed splits them)",
            )
        if self.settle >= self.duration - 2 * self.plant.pwm_period:
            raise field_error(
                "settle",
                f"{self.settle} s leaves fewer than two samples of duration "
                f"({self.duration} s); shorten settle",
            )
        if self.duration < len(self.reference.levels_deg) * self.plant.pwm_period:
            raise field_error(
                "duration", "shorter than one sample per level of the reference; lengthen it"
            )
        return self

    @property
    def steps(self) -> int:
        """Control periods simulated (one PWM period each)."""
        return round(self.duration / self.plant.pwm_period)


def reference_deg(reference: AngleReference, t: np.ndarray) -> np.ndarray:
    """θ_r at the sample times [°]; steps: the levels in order, each for an equal share of t.

    Args:
        reference: the reference's description.
        t: sample times, shape (n,) [s]; steps use only their number.

    Returns:
        θ_r at each sample, shape (n,) [°].
    """
    if reference.kind == "sinusoid":
        phase = 2 * math.pi * reference.frequency * t
        return reference.offset_deg - reference.amplitude_deg * np.cos(phase)
    levels = np.asarray(reference.levels_deg, dtype=float)
    index = np.minimum((np.arange(t.size) * levels.size) // t.size, levels.size - 1)
    return levels[index]


def simulate_trials(config: PneuNetPidConfig) -> ClosedLoopTrace:
    """Every trial of a config as one batch.

    Args:
        config: the experiment's config.

    Returns:
        The read-only trace: t [s] and reference [°], shape (n,); measured and true angle [°]
            and valve duty, shape (trials, n), one sample per PWM period.
    """
    t = np.arange(config.steps) * config.plant.pwm_period
    seeds = range(config.seed, config.seed + config.trials)
    controller = config.controller.build(config.trials)
    return run_closed_loop(config.plant, controller, reference_deg(config.reference, t), seeds)


def trial_metrics(config: PneuNetPidConfig, trace: ClosedLoopTrace) -> dict[str, np.ndarray]:
    """Per-trial E (2.7) on the sensor and on the true angle [°], and M (2.5).

    Args:
        config: the config the trace was run with (its `settle`).
        trace: the trace of every trial (simulate_trials).

    Returns:
        Name -> value per trial, shape (trials,): error, E on the sensor reading [°];
            error_true, E on the true angle [°]; cost, M (2.5) on the sensor reading (these
            three after `settle`); saturation, the fraction of PWM periods at duty 0 or 1.
    """
    keep = trace.t >= config.settle
    ref = trace.reference[keep]
    return {
        "error": tracking_error(ref, trace.measured[:, keep]),
        "error_true": tracking_error(ref, trace.theta[:, keep]),
        "cost": tuning_cost(trace.t[keep], ref, trace.measured[:, keep]),
        "saturation": np.mean((trace.duty <= 0) | (trace.duty >= 1), axis=1),
    }


def run_pneunet_pid(config: PneuNetPidConfig, progress: Progress | None = None) -> Result:
    """Simulate every trial; metrics are E's median and quartiles over trials, trace is trial 0.

    Args:
        config: the experiment's config.
        progress: not used: the trials run as one batch.

    Returns:
        Metrics error_median_deg, error_q1_deg and error_q3_deg (E on the sensor reading,
            over trials) and error_true_median_deg [°], cost_median (M) and
            saturation_fraction (mean over trials); trace of trial 0: t [s], theta_ref_deg,
            theta_meas_deg, theta_deg [°] and the valve duty (0-1).
    """
    trace = simulate_trials(config)
    m = trial_metrics(config, trace)
    q1, median, q3 = np.percentile(m["error"], [25, 50, 75])
    metrics = {
        "error_median_deg": float(median),
        "error_q1_deg": float(q1),
        "error_q3_deg": float(q3),
        "error_true_median_deg": float(np.median(m["error_true"])),
        "cost_median": float(np.median(m["cost"])),
        "saturation_fraction": float(np.mean(m["saturation"])),
    }
    columns = {
        "t": trace.t,
        "theta_ref_deg": trace.reference,
        "theta_meas_deg": trace.measured[0],
        "theta_deg": trace.theta[0],
        "duty": trace.duty[0],
    }
    return Result(metrics=metrics, trace=columns)


PNEUNET_PID = Experiment("pneunet.pid", PneuNetPidConfig, run_pneunet_pid)
