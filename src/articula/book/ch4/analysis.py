"""Chapter 4's results as numbers and claims: pure functions of the runs' metrics and the sweep."""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from articula.book.ch4 import book_values as book
from articula.book.claims import Claim, decide
from articula.book.text import degrees, milli, significant
from articula.loops.motor_current_linear import first_crossing

Runs = Mapping[str, Mapping[str, float]]  # figure run -> metrics (NaN: missing) and order "k"

# Thresholds of the rules.
OMEGA_C_TOLERANCE = 5e-5  # [rad/s]: half a unit of the book's last printed digit (8.1382)
OMEGA_PER_VOLT_TOLERANCE = 0.005  # [rad/(s·V)]: half a unit of the last digit of 2.81
CURRENT_PER_VOLT_TOLERANCE = 0.0005  # [A/V]: half a unit of the last digit of 0.015
RISE_TIME_FACTOR = 2.0  # "about 0.1 s": within this factor of the book's rise time either way
TRACKING_RATIO = 0.95  # amplitude ratio at or above which a sinusoid is tracked "easily"
HALF_POWER = 10 ** (-3 / 20)  # the −3 dB amplitude ratio that defines the bandwidth
SATURATION_SHARE = 0.05  # share of time at full PWM above which the linear prediction fails

# Claim names: chapters.ch4.claims keys of `reproduce --json`.
OMEGA_C = "omega_c matches the book"
PER_VOLT = "steady state per volt matches the book"
RISE_TIME = "fig4_5 rise time about 0.1 s"
TRACKS = "fig4_6 tracks 5 rad/s"
AMPLITUDE_FALLS = "fig4_7 amplitude falls at 25 rad/s"
LAG_GROWS = "fig4_7 phase lag grows at 25 rad/s"
FEEDBACK_RISE = "fig4_8 filtering lengthens the fed-back rise time"
CURRENT_RISE = "fig4_8 filtering lengthens the current's rise time"
FILTER_COSTS = "fig4_9 filter costs magnitude and phase at 5 rad/s"
LESS_NOISE = "filtering lowers feedback noise"
LESS_BANDWIDTH = "bandwidth falls with filter order"


@dataclass(frozen=True)
class BandwidthRow:
    """One filter order of the bandwidth sweep.

    Attributes:
        k: moving-average order of Eq. (4.17).
        frequencies: reference frequencies swept [rad/s], ascending.
        ratios: amplitude ratio of the true current at each, mean over seeds.
        measured: −3 dB bandwidth of the simulated sweep [rad/s] (inf: above the last one).
        predicted: −3 dB bandwidth of the linearised loop [rad/s] (NaN when unstable).
        stable: whether the linearised loop is stable.
        noise: feedback noise RMS [A], mean over the order's runs.
        low_frequency: the lowest frequency of the whole sweep [rad/s].
        error_low: tracking RMS error [A] at low_frequency, mean over seeds.
        saturation: largest share of time at full PWM among the order's runs.
    """

    k: int
    frequencies: np.ndarray
    ratios: np.ndarray
    measured: float
    predicted: float
    stable: bool
    noise: float
    low_frequency: float
    error_low: float
    saturation: float


@dataclass(frozen=True)
class Explanations:
    """Numbers that the report's explanations of a difference from the book quote.

    Attributes:
        implied_torque_constant: K [N·m/A] that would give the book's ω_ss/V and i_ss/V at
            Table 4.1's R.
        implied_friction: b [N·m·s/rad] that would do the same.
        book_ratio: the book's i_ss/ω_ss [A·s/rad], which is b/K by Eq. (4.8).
        proportional_gain: K_p/(K_p + R), what the proportional path alone passes.
        integral_corner: K_i/(K_p + R) [rad/s], below which the integral restores unity.
        tracking_loss: 1 − the amplitude ratio of Fig. 4.6.
        filter_delay: delay [s] of Fig. 4.9's moving average, (k − 1)/2 samples.
        filter_order: k of Fig. 4.9.
        saturated_orders: filter orders whose runs sit at full PWM over SATURATION_SHARE.
    """

    implied_torque_constant: float
    implied_friction: float
    book_ratio: float
    proportional_gain: float
    integral_corner: float
    tracking_loss: float
    filter_delay: float
    filter_order: int
    saturated_orders: tuple[int, ...]


def implied_constants(
    R: float, omega_per_volt: float, current_per_volt: float
) -> tuple[float, float]:
    """(K [N·m/A], b [N·m·s/rad]) that would give these ω_ss/V and i_ss/V through Eq. (4.8).

    Args:
        R: armature resistance [Ω].
        omega_per_volt: ω_ss/V [rad/(s·V)].
        current_per_volt: i_ss/V [A/V].
    """
    ratio = current_per_volt / omega_per_volt  # i_ss/ω_ss = b/K, Eq. (4.8) with τ_ex = 0
    K = 1.0 / omega_per_volt - R * ratio  # ω_ss/V = 1/(R·b/K + K)
    return K, ratio * K


def bandwidth_rows(
    columns: Mapping[str, Sequence[Any]], linear: Mapping[int, tuple[bool, float]]
) -> list[BandwidthRow]:
    """The bandwidth sweep summarised per filter order, ascending.

    Args:
        columns: the sweep's results table as arrays: controller.filter_order,
            reference.frequency [rad/s], amplitude_ratio, noise_rms [A], current_rms_error [A]
            and saturation_fraction, one entry per run (None for a missing metric).
        linear: filter order -> (linearised loop stable, its bandwidth [rad/s]).
    """
    k_col = np.asarray(columns["controller.filter_order"], dtype=float)
    f_col = np.asarray(columns["reference.frequency"], dtype=float)
    col = {
        name: np.asarray(columns[name], dtype=float)
        for name in (
            "amplitude_ratio",
            "noise_rms",
            "current_rms_error",
            "saturation_fraction",
        )
    }
    lowest = float(f_col.min())
    rows = []
    for k in sorted({int(k) for k in k_col}):
        sel = k_col == k
        freqs = np.unique(f_col[sel])
        ratio = np.array([col["amplitude_ratio"][sel & (f_col == f)].mean() for f in freqs])
        stable, predicted = linear[k]
        rows.append(
            BandwidthRow(
                k=k,
                frequencies=freqs,
                ratios=ratio,
                measured=first_crossing(freqs, ratio, HALF_POWER),
                predicted=predicted if stable else float("nan"),
                stable=stable,
                noise=float(col["noise_rms"][sel].mean()),
                low_frequency=lowest,
                error_low=float(col["current_rms_error"][sel & (f_col == lowest)].mean()),
                saturation=float(col["saturation_fraction"][sel].max()),
            )
        )
    return rows


def explanations(
    gains: Mapping[str, float], runs: Runs, rows: Sequence[BandwidthRow]
) -> Explanations:
    """The numbers behind the report's explanations.

    Args:
        gains: kp [V/A], ki [V/(A·s)], R [Ω] and dt [s] of the figure runs' loop.
        runs: metrics of each figure run, with its filter order under "k".
        rows: the bandwidth sweep per filter order.
    """
    kp, ki, R, dt = gains["kp"], gains["ki"], gains["R"], gains["dt"]
    K, b = implied_constants(R, book.OMEGA_PER_VOLT, book.CURRENT_PER_VOLT)
    k9 = int(runs["fig4_9"]["k"])
    return Explanations(
        implied_torque_constant=K,
        implied_friction=b,
        book_ratio=book.CURRENT_PER_VOLT / book.OMEGA_PER_VOLT,
        proportional_gain=kp / (kp + R),
        integral_corner=ki / (kp + R),
        tracking_loss=1.0 - runs["fig4_6"]["amplitude_ratio"],
        filter_delay=(k9 - 1) / 2 * dt,  # group delay of a k-sample mean, Eq. (4.17)
        filter_order=k9,
        saturated_orders=tuple(r.k for r in rows if r.saturation > SATURATION_SHARE),
    )


def _holds(holds: bool, *values: float) -> bool | None:
    """`holds`, or None (inconclusive) when a value it was decided on is NaN (missing)."""
    return None if any(math.isnan(v) for v in values) else holds


def model_claims(omega_c: float, omega_per_volt: float, current_per_volt: float) -> list[Claim]:
    """The model numbers of Sects. 4.2.2 and 4.3.2 against the book's.

    Args:
        omega_c: critical speed for Table 4.2 at 12 V and 1 A [rad/s].
        omega_per_volt: ω_ss/V for Table 4.1 [rad/(s·V)].
        current_per_volt: i_ss/V for Table 4.1 [A/V].
    """
    return [
        decide(
            OMEGA_C,
            book.SAYS_OMEGA_C,
            f"{omega_c:.6f} rad/s",
            f"within {OMEGA_C_TOLERANCE:g} rad/s of the book (half its last printed digit)",
            _holds(abs(omega_c - book.OMEGA_C) <= OMEGA_C_TOLERANCE, omega_c),
        ),
        decide(
            PER_VOLT,
            book.SAYS_PER_VOLT,
            f"{omega_per_volt:.4f} rad/(s·V) and {current_per_volt:.5f} A/V from Table 4.1",
            f"both within half a unit of the book's last printed digit "
            f"({OMEGA_PER_VOLT_TOLERANCE:g} rad/(s·V), {CURRENT_PER_VOLT_TOLERANCE:g} A/V)",
            _holds(
                abs(omega_per_volt - book.OMEGA_PER_VOLT) <= OMEGA_PER_VOLT_TOLERANCE
                and abs(current_per_volt - book.CURRENT_PER_VOLT) <= CURRENT_PER_VOLT_TOLERANCE,
                omega_per_volt,
                current_per_volt,
            ),
        ),
    ]


def run_claims(runs: Runs) -> list[Claim]:
    """What Sect. 4.4.1 says of Figs. 4.5-4.9, against the figure runs' metrics.

    Args:
        runs: metrics of each figure run (fig4_5 ... fig4_9): rise_time and rise_time_feedback
            [s], amplitude_ratio, phase_lag [rad], and its filter order under "k".
    """
    rise = runs["fig4_5"]["rise_time"]
    low, high = book.RISE_TIME / RISE_TIME_FACTOR, book.RISE_TIME * RISE_TIME_FACTOR
    a6, a7, a9 = (runs[n]["amplitude_ratio"] for n in ("fig4_6", "fig4_7", "fig4_9"))
    p6, p7, p9 = (runs[n]["phase_lag"] for n in ("fig4_6", "fig4_7", "fig4_9"))
    r5, r8 = runs["fig4_5"]["rise_time_feedback"], runs["fig4_8"]["rise_time_feedback"]
    t5, t8 = rise, runs["fig4_8"]["rise_time"]
    return [
        decide(
            RISE_TIME,
            book.SAYS_RISE_TIME,
            f"{milli(rise)} ms (10-90 % of the true current)",
            f"between {milli(low)} and {milli(high)} ms",
            _holds(low <= rise <= high, rise),
        ),
        decide(
            TRACKS,
            book.SAYS_TRACKS,
            f"amplitude ratio {significant(a6)}, phase lag {degrees(p6)}°",
            f"amplitude ratio at least {TRACKING_RATIO}",
            _holds(a6 >= TRACKING_RATIO, a6),
        ),
        decide(
            AMPLITUDE_FALLS,
            book.SAYS_AMPLITUDE_FALLS,
            f"amplitude ratio {significant(a7)} at 25 rad/s, {significant(a6)} at 5 rad/s",
            "smaller at 25 rad/s than at 5 rad/s (Fig. 4.6)",
            _holds(a7 < a6, a6, a7),
        ),
        decide(
            LAG_GROWS,
            book.SAYS_LAG_GROWS,
            f"phase lag {degrees(p7)}° at 25 rad/s, {degrees(p6)}° at 5 rad/s",
            "larger at 25 rad/s than at 5 rad/s (Fig. 4.6)",
            _holds(p7 > p6, p6, p7),
        ),
        decide(
            FEEDBACK_RISE,
            book.SAYS_FILTER_DELAYS,
            f"rise time of the fed-back signal {milli(r8)} ms filtered, {milli(r5)} ms unfiltered",
            "longer with the filter (Fig. 4.8) than without (Fig. 4.5)",
            _holds(r8 > r5, r5, r8),
        ),
        decide(
            CURRENT_RISE,
            book.SAYS_FILTER_DELAYS,
            f"rise time of the motor current {milli(t8)} ms filtered, {milli(t5)} ms unfiltered",
            "longer with the filter (Fig. 4.8) than without (Fig. 4.5)",
            _holds(t8 > t5, t5, t8),
        ),
        decide(
            FILTER_COSTS,
            book.SAYS_FILTER_COSTS,
            f"amplitude ratio {significant(a9)} filtered vs {significant(a6)} unfiltered, "
            f"phase lag {degrees(p9)}° vs {degrees(p6)}°",
            "smaller amplitude ratio and larger phase lag than unfiltered (Fig. 4.6)",
            _holds(a9 < a6 and p9 > p6, a6, a9, p6, p9),
        ),
    ]


def bandwidth_claims(rows: Sequence[BandwidthRow]) -> list[Claim]:
    """The chapter's trade-off (more filtering: less noise, less bandwidth) against the sweep.

    Args:
        rows: the bandwidth sweep per filter order, ascending.
    """
    orders = ", ".join(str(r.k) for r in rows)
    noise = [r.noise for r in rows]
    measured = [r.measured for r in rows]
    enough = len(rows) >= 2
    return [
        decide(
            LESS_NOISE,
            book.SAYS_LESS_NOISE,
            f"feedback noise RMS {', '.join(milli(n) for n in noise)} mA for k = {orders}",
            "never rises from one filter order to the next",
            _holds(all(b <= a for a, b in itertools.pairwise(noise)), *noise) if enough else None,
        ),
        decide(
            LESS_BANDWIDTH,
            book.SAYS_LESS_BANDWIDTH,
            f"−3 dB bandwidth of the simulated sweep "
            f"{', '.join(significant(m) for m in measured)} rad/s for k = {orders}",
            "falls from each filter order to the next",
            _holds(all(b < a for a, b in itertools.pairwise(measured)), *measured)
            if enough
            else None,
        ),
    ]


def claims(model: Mapping[str, float], runs: Runs, rows: Sequence[BandwidthRow]) -> list[Claim]:
    """Every claim of chapter 4 with the numbers that decide it.

    Args:
        model: omega_c [rad/s], omega_ss_per_volt [rad/(s·V)] and i_ss_per_volt [A/V].
        runs: metrics of each figure run, with its filter order under "k".
        rows: the bandwidth sweep per filter order, ascending.
    """
    per_volt = model_claims(model["omega_c"], model["omega_ss_per_volt"], model["i_ss_per_volt"])
    return [*per_volt, *run_claims(runs), *bandwidth_claims(rows)]
