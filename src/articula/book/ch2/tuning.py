"""Chapter 2 tuning runs on the simulated PneuNet: the manual procedure and coordinate descent.

Each evaluation of M (2.5) is one step experiment from rest on the simulated rig (fresh sensor
noise every time), so the tuners see exactly what they would see on a real rig.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from pydantic import Field

from articula.control.pid import PID, GainSchedule
from articula.experiments.pneunet import AngleReference, reference_deg
from articula.loops.pneunet_pid import SimulatedRig, run_closed_loop
from articula.plants.pneunet import PneuNetParams
from articula.tuning.coordinate_descent import DescentResult, coordinate_descent
from articula.tuning.manual import ManualResult, ManualSettings, manual_tuning
from articula.tuning.response import Response, readonly, step_features, tuning_cost
from articula.validation import Positive, Seed, StrictModel

GainVector = Annotated[list[Positive], Field(min_length=3, max_length=3)]
SUBRANGES = (15.0, 45.0, 75.0)  # representative points of [0,30), [30,60), [60,90] (Sect. 2.4.2.1)
SEQUENCE = (15.0, 45.0, 75.0, 90.0)  # whole-range tuning sequence (Fig. 2.6a)


class ManualConfig(StrictModel):
    """The scripted manual procedure: one step experiment per trial, `hold` seconds long.

    Attributes:
        seed: base of the noise seeds; the step to θ starts at seed + 100·int(θ) (manual_seed).
        hold: length of each step experiment [s].
        band: noise band about a level; swings inside it do not count [°].
        tolerance: acceptable steady-state error [°].
    """

    seed: Seed = 1000
    hold: Positive = 10.0
    band: Positive = 2.0
    tolerance: Positive = 1.0


class AutoConfig(StrictModel):
    """Coordinate descent (Algorithm 1): random K and dK, stop on |dK|_1 < k_stop or N sweeps.

    Gains (K_p, K_i, K_d) are in counts/°, counts/(°·s) and counts·s/°.

    Attributes:
        seed: seed of each run's random K and dK (with the run's index) and base of its noise
            seeds (auto_seed).
        hold: time each level of the reference is held [s].
        k_stop: the descent stops when |dK|_1 falls below it.
        max_iterations: most sweeps N over the three gains.
        k0_max: upper ends of the random start K ~ U(0, k0_max), (K_p, K_i, K_d).
        dk0_max: upper ends of the random steps dK ~ U(0, dk0_max), (K_p, K_i, K_d).
        upper: upper bounds on (K_p, K_i, K_d) (not in the book); a probe beyond them fails
            without an experiment.
    """

    seed: Seed = 2000
    hold: Positive = 4.0
    k_stop: Positive = 0.05
    max_iterations: Annotated[int, Field(ge=1, le=10_000)] = 30
    k0_max: GainVector = Field(default_factory=lambda: [2.0, 4.0, 0.2])
    dk0_max: GainVector = Field(default_factory=lambda: [0.5, 1.0, 0.1])
    upper: GainVector = Field(default_factory=lambda: [20.0, 40.0, 5.0])


class TuningConfig(StrictModel):
    """All tuning runs of the chapter.

    Attributes:
        manual: the manual procedure (Sect. 2.3.2.1, Fig. 2.5).
        auto: coordinate descent (Algorithm 1, Fig. 2.6).
        plant: the simulated PneuNet's constants.
    """

    manual: ManualConfig = ManualConfig()
    auto: AutoConfig = AutoConfig()
    plant: PneuNetParams = PneuNetParams()


@dataclass(frozen=True)
class TuningRun:
    """One coordinate-descent run and the reference levels it tuned on [°].

    Attributes:
        levels: the reference levels, held in order [°].
        result: the tuned gains K*, their cost M (2.5) and the state after every sweep.
    """

    levels: tuple[float, ...]
    result: DescentResult


def step_reference(levels: tuple[float, ...], hold: float, period: float) -> np.ndarray:
    """Levels [°] held `hold` seconds each, sampled every PWM period (reference_deg, steps).

    Args:
        levels: the levels, in order [°].
        hold: time each level is held [s].
        period: sample interval, the PWM period [s].

    Returns:
        θ_r at each sample, shape (len(levels)·round(hold / period),) [°].
    """
    steps = len(levels) * round(hold / period)
    config = AngleReference(kind="steps", levels_deg=[float(v) for v in levels])
    return reference_deg(config, np.arange(steps) * period)


def manual_run(config: TuningConfig, level: float) -> ManualResult:
    """The manual procedure on steps from rest to `level` [°].

    Args:
        config: the tuning config (its `manual` and `plant`).
        level: the step's target [°].

    Returns:
        The chosen gains (K_p, K_i, K_d) and every experiment with its decision.

    Raises:
        InfeasibleError: the smallest K_p already gives swings that grow or persist.
    """
    m = config.manual
    reference = step_reference((level,), m.hold, config.plant.pwm_period)
    rig = SimulatedRig(config.plant, reference, manual_seed(config, level))
    settings = ManualSettings(band=m.band, tolerance=m.tolerance)
    return manual_tuning(rig, settings)


def auto_run(
    config: TuningConfig,
    levels: tuple[float, ...],
    index: int,
    rig: Callable[[np.ndarray], Response] | None = None,
) -> TuningRun:
    """Coordinate descent of M (2.5) on steps through `levels` [°]; `index` picks the seed.

    Args:
        config: the tuning config (its `auto` and `plant`).
        levels: the reference levels, held in order [°].
        index: number of the run: seeds its random K and dK, with `auto.seed`, and its noise
            (auto_seed).
        rig: runs one experiment with gains K = (K_p, K_i, K_d) and returns its response [°];
            None: the simulated actuator (SimulatedRig, noise seed `auto_seed(config,
            index)`), else, e.g., rigs.pneunet.PneuNetRig on a real or emulated rig with the
            same program.

    Returns:
        The levels and the descent's result: the tuned gains, their cost and every sweep.
    """
    a = config.auto
    rng = np.random.default_rng([a.seed, index])
    if rig is None:
        reference = step_reference(levels, a.hold, config.plant.pwm_period)
        rig = SimulatedRig(config.plant, reference, auto_seed(config, index))

    def cost(k: np.ndarray) -> float:
        r = rig(k)
        return float(tuning_cost(r.t, r.reference, r.measured))  # M(K), Eq. (2.5)

    k0 = rng.uniform(0.0, a.k0_max)  # K ← random 3×1 vector (Algorithm 1)
    dk0 = rng.uniform(0.0, a.dk0_max) + 1e-6  # dK ← positive random 3×1 vector
    result = coordinate_descent(
        cost, k0, dk0, a.k_stop, a.max_iterations, lower=np.zeros(3), upper=np.array(a.upper)
    )
    return TuningRun(levels, result)


def manual_seed(config: TuningConfig, level: float) -> int:
    """The first noise seed of the manual procedure on a step to `level` [°].

    Args:
        config: the tuning config (its `manual.seed`).
        level: the step's target [°].

    Returns:
        manual.seed + 100·int(level).
    """
    return config.manual.seed + int(level) * 100


def auto_seed(config: TuningConfig, index: int) -> int:
    """The first noise seed of tuning run `index` (each experiment of the run takes the next).

    Args:
        config: the tuning config (its `auto.seed`).
        index: number of the tuning run.

    Returns:
        1000·auto.seed + 100 000·index.
    """
    return config.auto.seed * 1000 + index * 100_000


@dataclass(frozen=True, eq=False)
class KdProbe:
    """Paired experiments of one gain set with its K_d replaced by each value of `kd`.

    The arrays are read-only; n is the number of experiments per K_d.

    Attributes:
        kd: the K_d values tried [counts·s/°].
        cost: M (2.5) per K_d and experiment, shape (len(kd), n).
        swings: swings of the sensor reading beyond the noise band about each level, summed
            over the levels, shape (len(kd), n).
        sustained: whether some level's swings do not die out (StepFeatures.sustained),
            shape (len(kd), n).
    """

    kd: tuple[float, ...]
    cost: np.ndarray
    swings: np.ndarray
    sustained: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "cost", readonly(self.cost))
        object.__setattr__(self, "swings", readonly(self.swings))
        sustained = np.array(self.sustained, dtype=bool)
        sustained.setflags(write=False)
        object.__setattr__(self, "sustained", sustained)


def kd_probe(
    plant: PneuNetParams,
    gains: np.ndarray,
    levels: tuple[float, ...],
    hold: float,
    kd_values: tuple[float, ...],
    seeds: int,
    band: float,
) -> KdProbe:
    """M (2.5) and swings of `seeds` step experiments for the gains with K_d set to each value.

    Every K_d sees the same noise seeds, so differences between K_d values are paired; the
    experiments run as one batch, which gives the numbers of running them one by one.

    Args:
        plant: the simulated PneuNet's constants (the nominal actuator in every experiment).
        gains: the gain set (K_p, K_i, K_d); its K_p and K_i are kept.
        levels: the reference levels, held in order [°].
        hold: time each level is held [s].
        kd_values: the K_d values to try [counts·s/°].
        seeds: number of experiments per K_d (noise seeds 50 000, 50 001, …).
        band: noise band of the swing count [°].

    Returns:
        Per K_d and experiment, shape (len(kd_values), seeds): the cost M, the swings and
            whether they are sustained.
    """
    reference = step_reference(levels, hold, plant.pwm_period)
    per_level = reference.size // len(levels)
    seeds_used = range(50_000, 50_000 + seeds)
    cost, swings, sustained = [], [], []
    for kd in kd_values:
        schedule = GainSchedule("constant", np.array([[gains[0], gains[1], kd]]))
        pid = PID(schedule, (0.0, 255.0))
        trace = run_closed_loop(plant, pid, reference, seeds_used, vary=False)
        cost.append(tuning_cost(trace.t, trace.reference, trace.measured))
        count = np.zeros(seeds, dtype=int)
        lasting = np.zeros(seeds, dtype=bool)
        for j in range(len(levels)):
            part = slice(j * per_level, (j + 1) * per_level)
            for i in range(seeds):
                r = Response(trace.t[part], trace.reference[part], trace.measured[i, part])
                f = step_features(r, band)
                count[i] += f.peak_sizes.size
                lasting[i] |= f.sustained()
        swings.append(count)
        sustained.append(lasting)
    return KdProbe(tuple(kd_values), np.array(cost), np.array(swings), np.array(sustained))
