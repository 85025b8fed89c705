"""Chapter 2's results as numbers and claims: pure functions of the tuning, probes and sweep."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.stats import spearmanr

from articula.book.ch2.book_values import (
    BOOK_TABLE_2_3,
    CLAIMS,
    CONTROLLERS,
    FREQUENCIES,
    KINDS,
    METHODS,
    SCHEDULED,
)
from articula.book.ch2.kd_analysis import (
    NOISE_ERRORS,
    DescentKd,
    KdSummary,
    descent_kd,
    kd_summary,
    kd_zero_status,
    tried_kd,
)
from articula.book.ch2.study import FULL_KEY, Ch2Results, Row
from articula.book.ch2.tuning import TuningRun
from articula.book.claims import Claim, Verdict, decide
from articula.errors import ConfigError
from articula.tuning.manual import ManualResult

Table = Mapping[str, Mapping[float, Row]]  # controller -> frequency [Hz] -> Row
MAJORITY = 0.5  # "in most cases": wins in more than this share of the comparisons
GROWTH_CORRELATION = 0.8  # "grows with frequency": Spearman ρ of median E at least this
HIGH_FREQUENCIES = (2.0, 5.0)  # [Hz] compared with an actuator that stays still
KD_OURS = {
    "reproduced": "for every tuned gain set no K_d > 0 lowers M (2.5) beyond its noise and "
    "some K_d > 0 makes it clearly worse",
    "not reproduced": "for at least one tuned gain set some K_d > 0 lowers M (2.5) beyond "
    "its noise",
    "inconclusive": "no K_d > 0 lowers M (2.5) beyond its noise, but for at least one tuned "
    "gain set no K_d > 0 probed is clearly worse either, so the data cannot tell",
}


@dataclass(frozen=True)
class Misprint:
    """A book entry of Table 2.3 whose quartiles do not bracket its median."""

    controller: str
    frequency: float  # [Hz]
    row: Row


@dataclass(frozen=True)
class Span:
    """Medians at one frequency [Hz]: ours and the book's range [°], and how many of the
    book's lie above a still actuator's E."""

    frequency: float
    ours: tuple[float, float]
    book: tuple[float, float]
    book_above_still: int
    book_count: int


@dataclass(frozen=True)
class Findings:
    """What the report states beside the raw results: the K_d probe by gain set with its
    verdict, the descents' and the manual procedure's K_d, the manual levels that missed the
    tolerance, the lowest median at each frequency [Hz], the book's misprints, a still
    actuator's E [°] and the high-frequency spans, the calibration fits (amplitude ratio, lag
    [rad]) by frequency, and the Ziegler-Nichols PID K_p over the manual one at 90°."""

    kd: dict[str, KdSummary]
    kd_status: Verdict
    descent: dict[str, DescentKd]
    manual_kd: dict[str, tuple[float, ...]]
    missed: tuple[str, ...]
    lowest: dict[float, float]
    misprints: tuple[Misprint, ...]
    still: float
    spans: tuple[Span, ...]
    calibration: dict[float, tuple[float, float]]
    zn_kp_ratio: float


def findings(results: Ch2Results) -> Findings:
    """Every number the report derives from the results."""
    tuning, comparison = results.tuning, results.comparison
    kd = {name: kd_summary(p) for name, p in results.probes.items()}
    still = still_error(comparison.amplitude_deg)
    return Findings(
        kd=kd,
        kd_status=kd_zero_status({name: s.verdict for name, s in kd.items()}),
        descent={k: descent_kd(r) for k, r in tuning.auto.items()},
        manual_kd={k: tried_kd(r) for k, r in tuning.manual.items()},
        missed=missed_tolerance(tuning.manual),
        lowest=lowest_medians(comparison.table),
        misprints=tuple(misprints(BOOK_TABLE_2_3)),
        still=still,
        spans=tuple(spans(comparison.table, BOOK_TABLE_2_3, still)),
        calibration={f: amplitude_and_lag(t, f) for f, t in comparison.calibration.items()},
        zn_kp_ratio=float(tuning.zn.pid[0] / tuning.manual[FULL_KEY].gains[0]),
    )


def missed_tolerance(manual: Mapping[str, ManualResult]) -> tuple[str, ...]:
    """Levels whose manual K_i ladder did not reach the steady-state tolerance."""
    return tuple(k for k, r in manual.items() if not r.within_tolerance)


def medians(table: Table) -> dict[str, np.ndarray]:
    """Median E [°] of each controller at FREQUENCIES."""
    return {n: np.array([table[n][f][0] for f in FREQUENCIES]) for n in CONTROLLERS}


def lowest_medians(table: Table) -> dict[float, float]:
    """The lowest median E [°] over the controllers at each frequency [Hz]."""
    return {f: min(table[n][f][0] for n in CONTROLLERS) for f in FREQUENCIES}


def auto_wins(table: Table) -> tuple[int, int]:
    """(wins, cases): (kind, frequency) pairs where automatic tuning has the lower median E."""
    med = medians(table)
    wins = sum(int(np.sum(med[f"{k}-auto"] < med[f"{k}-manual"])) for k in KINDS)
    return wins, len(KINDS) * len(FREQUENCIES)


def scheduled_wins(table: Table) -> tuple[int, int]:
    """(wins, cases): a scheduled controller against the ordinary one with the same tuning, at
    each frequency, with the lower median E."""
    med = medians(table)
    wins = sum(
        int(np.sum(med[f"{k}-{m}"] < med[f"ordinary-{m}"])) for k in SCHEDULED for m in METHODS
    )
    return wins, len(SCHEDULED) * len(METHODS) * len(FREQUENCIES)


def rank_correlations(table: Table) -> dict[str, float]:
    """Spearman correlation of each controller's median E with frequency; 0 when flat."""
    return {n: _rank_correlation(m) for n, m in medians(table).items()}


def _rank_correlation(values: np.ndarray) -> float:
    """Spearman correlation of values with FREQUENCIES; 0 when the values are all equal."""
    if np.all(values == values[0]):
        return 0.0
    return float(spearmanr(FREQUENCIES, values).statistic)


def claims(table: Table, kd_status: Verdict) -> list[Claim]:
    """The chapter's four claims, each decided by the numbers it quotes.

    Args:
        table: controller -> frequency [Hz] -> (median, Q1, Q3) of E [°] for every name of
            CONTROLLERS and frequency of FREQUENCIES.
        kd_status: kd_zero_status's verdict, taken as the verdict of kd_zero_optimal.

    Returns:
        automatic_beats_manual, piecewise_fuzzy_beat_ordinary, error_grows_with_frequency and
        kd_zero_optimal, in that order.
    """
    if kd_status not in KD_OURS:
        raise ConfigError("kd_status", f"unknown {kd_status!r}; use one of {tuple(KD_OURS)}")
    auto, cases = auto_wins(table)
    scheduled, comparisons = scheduled_wins(table)
    rho = rank_correlations(table)
    return [
        decide(
            "automatic_beats_manual",
            CLAIMS["automatic_beats_manual"],
            f"lower median E in {auto} of {cases} (controller kind, frequency) pairs",
            f"automatic tuning has the lower median E in more than {MAJORITY:.0%} of the pairs "
            "(ties count for neither)",
            auto > cases * MAJORITY,
            "Automatic tuning beats manual in most cases",
        ),
        decide(
            "piecewise_fuzzy_beat_ordinary",
            CLAIMS["piecewise_fuzzy_beat_ordinary"],
            f"lower median E in {scheduled} of {comparisons} comparisons (each scheduled "
            "controller against the ordinary one with the same tuning, at each frequency)",
            f"the scheduled controller has the lower median E in more than {MAJORITY:.0%} of "
            "the comparisons (ties count for neither)",
            scheduled > comparisons * MAJORITY,
            "Piecewise and fuzzy PID beat ordinary PID",
        ),
        decide(
            "error_grows_with_frequency",
            CLAIMS["error_grows_with_frequency"],
            "Spearman rank correlation of median E with frequency, "
            + ", ".join(f"{n} {r:.2f}" for n, r in rho.items()),
            f"every controller's correlation is at least {GROWTH_CORRELATION}",
            all(r >= GROWTH_CORRELATION for r in rho.values()),
            "The tracking error grows with the reference frequency",
        ),
        Claim(
            "kd_zero_optimal",
            CLAIMS["kd_zero_optimal"],
            f"{KD_OURS[kd_status]} (the K_d probe table)",
            "reproduced if for every tuned gain set no K_d > 0 lowers M beyond "
            f"{NOISE_ERRORS:g} standard errors of the paired differences and some K_d > 0 "
            "raises it as much or swings without dying out; not reproduced if some K_d > 0 "
            "lowers it for some set; inconclusive otherwise",
            kd_status,
            "K_d = 0 is optimal",
        ),
    ]


def misprints(book: Mapping[str, Sequence[Row]]) -> list[Misprint]:
    """Book entries (rows at FREQUENCIES) whose printed quartiles do not bracket the median."""
    return [
        Misprint(name, FREQUENCIES[i], (med, q1, q3))
        for name, rows in book.items()
        for i, (med, q1, q3) in enumerate(rows)
        if not q1 <= med <= q3
    ]


def still_error(amplitude: float) -> float:
    """E (2.7) [°] of an actuator resting at the offset of a sinusoid of this amplitude [°]:
    the mean of |A·cos| over a period, 2A/π."""
    return 2 * amplitude / math.pi


def spans(table: Table, book: Mapping[str, Sequence[Row]], still: float) -> list[Span]:
    """Our and the book's medians at HIGH_FREQUENCIES, against a still actuator's E [°]."""
    result = []
    for f in HIGH_FREQUENCIES:
        i = FREQUENCIES.index(f)
        theirs = [rows[i][0] for rows in book.values()]
        ours = [table[n][f][0] for n in CONTROLLERS]
        above = sum(b > still for b in theirs)
        result.append(
            Span(f, (min(ours), max(ours)), (min(theirs), max(theirs)), above, len(theirs))
        )
    return result


def amplitude_and_lag(trace: Mapping[str, np.ndarray], f: float) -> tuple[float, float]:
    """Amplitude ratio and phase lag [rad] of the sensor reading at frequency f [Hz], fitted
    by least squares over the second half of the trace (past the start from rest)."""
    t = trace["t"]
    keep = t >= t[-1] / 2
    w = 2 * np.pi * f
    basis = np.stack([np.ones(keep.sum()), np.sin(w * t[keep]), np.cos(w * t[keep])], axis=1)
    ref = np.linalg.lstsq(basis, trace["theta_ref_deg"][keep], rcond=None)[0]
    out = np.linalg.lstsq(basis, trace["theta_meas_deg"][keep], rcond=None)[0]
    ratio = np.hypot(out[1], out[2]) / np.hypot(ref[1], ref[2])
    lag = np.angle(complex(ref[1], ref[2])) - np.angle(complex(out[1], out[2]))
    return float(ratio), float((lag + np.pi) % (2 * np.pi) - np.pi)


def gain_dict(k: Sequence[float]) -> dict[str, float]:
    """[K_p, K_i, K_d] as {"kp", "ki", "kd"}."""
    return {"kp": float(k[0]), "ki": float(k[1]), "kd": float(k[2])}


def table_data(table: Table) -> dict[str, dict[str, list[float]]]:
    """Table 2.3 for --json: controller -> "f" (as printed by :g) -> [median, Q1, Q3]."""
    return {name: {f"{f:g}": list(row) for f, row in rows.items()} for name, rows in table.items()}


def tuning_data(
    manual: Mapping[str, ManualResult], auto: Mapping[str, TuningRun]
) -> dict[str, Any]:
    """Table 2.2 for --json: manual and auto -> key -> gain_dict."""
    return {
        "manual": {k: gain_dict(r.gains) for k, r in manual.items()},
        "auto": {k: gain_dict(r.result.k) for k, r in auto.items()},
    }
