"""Chapter 3 experiment: actuate one side, hold, deactuate, with or without active damping."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field, model_validator

from articula.control.damping import DampingPolicy
from articula.loops.six_chamber import Deactuation, deactuate, valve_program
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import CHAMBERS, SixChamberParams, chamber_directions
from articula.runs.registry import Experiment, Progress, Result
from articula.validation import Positive, Seed, StrictModel, field_error

RECORD_DT = 1e-3  # [s] trace sample interval
MIN_SAMPLES_AFTER = 2  # sensor samples after deactuation: the metrics need a start and a change


class DeactuationConfig(StrictModel):
    """One actuate-hold-deactuate run of Sect. 3.4 (Fig. 3.7); times [s], pressures gauge [Pa].

    The side is filled at t = 0 and held at its pressure (a chamber below supply is
    pressure-regulated: its fill valve reopens whenever the bend lets its pressure fall),
    vented at t = hold, and the run ends `after` seconds later.

    Attributes:
        seed: seed of the orientation sensor's noise.
        dt: RK4 integration step, at most 1 ms and dividing the 1 ms trace interval [s].
        hold: time from filling the side (t = 0) to venting it [s].
        after: time simulated after the vent [s].
        side_deg: the pressurised side, chamber i at 60°·i; between chambers the two nearest
            share it [deg].
        pressure: gauge pressure the side is held at [Pa]; None: the pump's supply.
        band_deg: settling band about rest [deg].
        actuator: the six-chamber actuator's constants, valves and air.
        sensor: the orientation sensor's rate and noise.
        damping: the active-damping pulse on the opposite side, Eq. (3.4); δ = 0: none.
    """

    seed: Seed = 0
    dt: Annotated[float, Field(gt=0, le=1e-3, allow_inf_nan=False)] = 1e-4
    hold: Positive = 1.5
    after: Positive = 2.0
    side_deg: Annotated[float, Field(ge=-360, le=360, allow_inf_nan=False)] = 0.0
    pressure: Positive | None = None
    band_deg: Positive = 1.0
    actuator: SixChamberParams = SixChamberParams()
    sensor: OrientationSensorParams = OrientationSensorParams()
    damping: DampingPolicy = DampingPolicy()

    @model_validator(mode="after")
    def _check(self) -> DeactuationConfig:
        if self.pressure is not None and self.pressure > self.actuator.supply:
            raise field_error(
                "pressure",
                f"pressure ({self.pressure:g} Pa) is above the supply "
                f"({self.actuator.supply:g} Pa); lower it or raise actuator.supply",
            )
        if (self.hold + self.after) / self.dt > 5_000_000:
            raise field_error(
                "dt",
                f"(hold + after)/dt is over 5e6 steps (dt = {self.dt:g} s); raise dt or shorten "
                "the run",
            )
        if abs(round(RECORD_DT / self.dt) * self.dt - RECORD_DT) > 1e-12:
            raise field_error(
                "dt",
                f"dt ({self.dt:g} s) must divide the {RECORD_DT:g} s trace interval, e.g. 1e-4",
            )
        if self.after * min(self.sensor.rate, 1 / RECORD_DT) < MIN_SAMPLES_AFTER:
            raise field_error(
                "after",
                f"{self.after:g} s after the vent command holds fewer than {MIN_SAMPLES_AFTER} "
                f"samples at the sensor's {self.sensor.rate:g} Hz; lengthen after or raise "
                "sensor.rate",
            )
        return self

    @property
    def gauge(self) -> float:
        """Deactuation pressure [Pa] of the pressurised side (the denominator of Eq. 3.4)."""
        return self.actuator.supply if self.pressure is None else self.pressure


def simulate_deactuation(config: DeactuationConfig) -> Deactuation:
    """Run the plant and the sensor for one config.

    Args:
        config: the run's config.

    Returns:
        The plant's samples (every 1 ms), the sensor's samples, the bending direction and
            the deactuation instant.
    """
    program = valve_program(
        config.actuator, config.side_deg, config.gauge, config.hold, config.damping
    )
    return deactuate(
        config.actuator,
        config.sensor,
        program,
        config.side_deg,
        config.hold,
        config.after,
        config.dt,
        round(RECORD_DT / config.dt),
        np.random.default_rng(config.seed),
    )


def oscillation_metrics(
    t: np.ndarray, angle: np.ndarray, t_off: float, band: float
) -> dict[str, float]:
    """Peak, overshoot and settling of a signed angle [rad] (positive toward the bend) after t_off.

    Args:
        t: sample times, shape (n,) [s].
        angle: signed bending angle at those times, shape (n,) [rad].
        t_off: deactuation instant [s].
        band: settling band about rest [rad].

    Returns:
        Metric name -> value: peak, the largest |angle| after it first crosses rest (0 if it
            never does) [rad]; overshoot, the largest swing past rest over the angle at
            deactuation (NaN if that angle is not positive); settling, the time after t_off
            from which |angle| stays within band [s] (NaN if it never does); start, the
            angle at deactuation [rad].
    """
    after = t >= t_off - 1e-12
    ta, a = t[after], angle[after]
    start = a[0]
    crossed = np.nonzero(a <= 0)[0]
    peak = float(np.max(np.abs(a[crossed[0] :]))) if crossed.size else 0.0
    overshoot = float(max(0.0, -a.min()) / start) if start > 0 else float("nan")
    outside = np.nonzero(np.abs(a) > band)[0]
    if not outside.size:
        settling = 0.0
    elif outside[-1] + 1 < ta.size:
        settling = float(ta[outside[-1] + 1] - t_off)
    else:  # still outside the band when the run ends
        settling = float("nan")
    return {"peak": peak, "overshoot": overshoot, "settling": settling, "start": float(start)}


def run_metrics(run: Deactuation, band_deg: float) -> dict[str, float]:
    """Metrics on the sensor (as the book measured) and on the true angle.

    Settling times are sample instants, rounded to 1 µs to drop float noise (0.93, not
    0.9300000000000002).

    Args:
        run: the simulated run (simulate_deactuation).
        band_deg: settling band about rest [deg].

    Returns:
        Metric name -> value. On the sensor: peak_deg [deg], overshoot_pct [%], settling_s
            [s] (NaN: not settled by the end) and deactuation_angle_deg [deg]; on the true
            angle: peak_true_deg [deg], overshoot_true_pct [%] and settling_true_s [s];
            opposite_peak_pressure, the largest gauge pressure after deactuation in the
            chambers on the side bent toward [Pa].
    """
    band = np.radians(band_deg)
    sensed = oscillation_metrics(run.sensor_t, run.sensor_bend @ run.direction, run.t_off, band)
    true = oscillation_metrics(run.sim.t, run.sim.beta @ run.direction, run.t_off, band)
    for m in (sensed, true):
        m["settling"] = round(m["settling"], 6)  # nan stays nan
    return {
        "peak_deg": float(np.degrees(sensed["peak"])),
        "overshoot_pct": 100 * sensed["overshoot"],
        "settling_s": sensed["settling"],
        "deactuation_angle_deg": float(np.degrees(sensed["start"])),
        "peak_true_deg": float(np.degrees(true["peak"])),
        "overshoot_true_pct": 100 * true["overshoot"],
        "settling_true_s": true["settling"],
        "opposite_peak_pressure": float(_opposite_peak(run)),
    }


def _opposite_peak(run: Deactuation) -> float:
    """Largest gauge pressure [Pa] after deactuation in the chambers on the side bent toward."""
    after = run.sim.t >= run.t_off
    far = chamber_directions() @ run.direction > 1e-9
    return float(run.sim.gauge[after][:, far].max())


def run_deactuation(config: DeactuationConfig, progress: Progress | None = None) -> Result:
    """Simulate one run; metrics on the sensor signal and the truth, trace at 1 kHz.

    Args:
        config: the run's config.
        progress: not used: the run reports no progress.

    Returns:
        The metrics of run_metrics and the trace: t [s]; bend, the true bending angle toward
            the side, its components bend_x and bend_y, and bend_sensor, the sensor's latest
            sample toward the side [rad]; p0-p5, the chambers' gauge pressures [Pa];
            valve0-valve5, their valve modes.
    """
    run = simulate_deactuation(config)
    sim = run.sim
    held = np.searchsorted(run.sensor_t, sim.t, side="right") - 1
    trace = {
        "t": sim.t,
        "bend": sim.beta @ run.direction,
        "bend_x": sim.beta[:, 0],
        "bend_y": sim.beta[:, 1],
        "bend_sensor": run.sensor_bend[held] @ run.direction,
        **{f"p{i}": sim.gauge[:, i] for i in range(CHAMBERS)},
        **{f"valve{i}": sim.modes[:, i].astype(float) for i in range(CHAMBERS)},
    }
    return Result(metrics=run_metrics(run, config.band_deg), trace=trace)


DAMPING = Experiment("softarm.damping", DeactuationConfig, run_deactuation)
