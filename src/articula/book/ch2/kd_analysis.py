"""Is K_d = 0 optimal (Sect. 2.4.2.1)? Verdicts of the K_d probes, and the tuners' K_d."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from articula.book.ch2.tuning import KdProbe, TuningRun
from articula.book.claims import Verdict
from articula.errors import ConfigError
from articula.tuning.manual import ManualResult

NOISE_ERRORS = 2.0  # a K_d changes M beyond noise: mean paired difference > this many SE
SWINGING_SHARE = 0.5  # a K_d swings: sustained swings in more than this share of experiments


@dataclass(frozen=True)
class KdVerdict:
    """What one gain set's K_d probe shows: K_d > 0 values that lower mean M beyond noise
    (`better`), that raise it beyond noise or swing without dying out (`worse`), and the K_d
    of the lowest mean M."""

    better: tuple[float, ...]
    worse: tuple[float, ...]
    lowest: float


@dataclass(frozen=True, eq=False)
class KdSummary:
    """One gain set's probe per K_d: mean M (2.5), median swing count, how many experiments
    swing without dying out, and the verdict."""

    mean_cost: np.ndarray
    median_swings: np.ndarray
    sustained: np.ndarray
    verdict: KdVerdict


@dataclass(frozen=True)
class DescentKd:
    """K_d and its step dK_d in one coordinate-descent run: random start and final values."""

    start: float
    final: float
    moved: bool
    step_start: float
    step_final: float


def kd_verdict(probe: KdProbe) -> KdVerdict:
    """Compare each K_d > 0 with K_d = 0 (probe.kd[0] must be 0) on the paired experiments.

    Beyond noise: the mean paired difference of M (2.5) exceeds NOISE_ERRORS standard errors.
    Swinging: sustained swings in more than SWINGING_SHARE of the experiments while K_d = 0
    has them in at most that share.
    """
    if not probe.kd or probe.kd[0] != 0.0:
        raise ConfigError("kd", f"the first K_d of a probe must be 0 (got {probe.kd})")
    n = probe.cost.shape[1]
    base_swinging = np.mean(probe.sustained[0]) > SWINGING_SHARE
    better, worse = [], []
    for j, kd in enumerate(probe.kd[1:], start=1):
        diff = probe.cost[j] - probe.cost[0]
        noise = NOISE_ERRORS * np.std(diff, ddof=1) / np.sqrt(n) if n > 1 else 0.0
        mean = float(np.mean(diff))
        swinging = np.mean(probe.sustained[j]) > SWINGING_SHARE and not base_swinging
        if mean < 0 and mean < -noise:
            better.append(kd)
        elif (mean > 0 and mean > noise) or swinging:
            worse.append(kd)
    means = probe.cost.mean(axis=1)
    return KdVerdict(tuple(better), tuple(worse), probe.kd[int(np.argmin(means))])


def kd_summary(probe: KdProbe) -> KdSummary:
    """The probe's numbers per K_d as the report shows them, with its verdict."""
    return KdSummary(
        probe.cost.mean(axis=1),
        np.median(probe.swings, axis=1),
        probe.sustained.sum(axis=1),
        kd_verdict(probe),
    )


def kd_zero_status(verdicts: Mapping[str, KdVerdict]) -> Verdict:
    """The claim "K_d = 0 is optimal" over every probed gain set.

    reproduced: for every set no K_d > 0 is better beyond noise and some K_d > 0 is clearly
    worse; not reproduced: some K_d > 0 is better beyond noise for some set; inconclusive:
    neither (a set where K_d made no difference either way).
    """
    if not verdicts:
        raise ConfigError("verdicts", "need at least one probed gain set")
    if any(v.better for v in verdicts.values()):
        return "not reproduced"
    if all(v.worse for v in verdicts.values()):
        return "reproduced"
    return "inconclusive"


def descent_kd(run: TuningRun) -> DescentKd:
    """Where a coordinate-descent run started and ended in K_d, and whether K_d ever moved."""
    history = run.result.history
    start = history[0]
    moved = any(h.k[2] != start.k[2] for h in history)
    return DescentKd(
        float(start.k[2]),
        float(run.result.k[2]),
        moved,
        float(start.dk[2]),
        float(history[-1].dk[2]),
    )


def tried_kd(result: ManualResult) -> tuple[float, ...]:
    """The K_d > 0 values the manual procedure tried, smallest first."""
    return tuple(sorted({float(t.gains[2]) for t in result.trials if t.gains[2] > 0}))
