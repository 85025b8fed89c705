"""Chapter 2's report section: formats tuning, comparison and the K_d probe; no computing."""

from __future__ import annotations

import math
from collections.abc import Iterable

from articula.book.ch2.analysis import Findings, Misprint, Span
from articula.book.ch2.book_values import (
    BOOK_TABLE_2_2,
    BOOK_TABLE_2_3,
    CONTROLLERS,
    FREQUENCIES,
    SINUSOID_FIGURES,
    TRACKING_LIMIT,
)
from articula.book.ch2.kd_analysis import NOISE_ERRORS
from articula.book.ch2.study import (
    FULL_KEY,
    KD_PROBE,
    KD_PROBE_SEEDS,
    SWEEP,
    Ch2Results,
    Comparison,
    Tuning,
)
from articula.book.text import fixed


def markdown(results: Ch2Results, findings: Findings) -> str:
    """The section: tuning (Table 2.2), comparison (Table 2.3), the K_d probe."""
    lines = [
        *_tuning_lines(results.tuning, findings),
        *_comparison_lines(results.comparison, findings),
        *_kd_lines(results.tuning, findings),
    ]
    return "\n".join(lines)


def gains(k: Iterable[float]) -> str:
    """K_p, K_i, K_d to three significant digits."""
    return ", ".join(f"{float(g):.3g}" for g in k)


def _kd_list(values: Iterable[float]) -> str:
    """K_d values as a comma list, or "none"."""
    return ", ".join(f"{k:g}" for k in values) or "none"


def _tuning_lines(tuning: Tuning, findings: Findings) -> list[str]:
    """Table 2.2 ours beside the book's, Ziegler-Nichols, Figs. 2.5 and 2.6."""
    m, a = tuning.config.manual, tuning.config.auto
    manual, auto, zn = tuning.manual, tuning.auto, tuning.zn
    lines = [
        "### Tuning (Sect. 2.3.2, 2.4.2.1): Table 2.2, Figs. 2.5 and 2.6",
        "",
        "The book tuned a real PneuNet; we tune a simulated one (`plants/pneunet.py`, parameters "
        "and their reasons in docs/deviations.md). Gains are in the book's units: the output is "
        "the 8-bit PWM value, the error is in degrees. Manual: the procedure of Sect. 2.3.2.1 "
        f"scripted on {m.hold:g} s steps from rest (K_p raised ×1.5 until the "
        "response oscillates with shrinking swings, then K_i ×1.5 until the steady-state error "
        f"is within {m.tolerance:g}°, then K_d from 0.01 ×2, always at least one "
        "experiment, kept only while it lowers the overshoot by more than the "
        f"{m.band:g}° noise band without more swings). Automatic: Algorithm 1 "
        f"minimising M (2.5), random K ~ U(0, {a.k0_max}) and dK ~ U(0, {a.dk0_max}), "
        f"K_stop = {a.k_stop:g}, N = {a.max_iterations} sweeps, {a.hold:g} s per reference "
        "level; every evaluation of M is one experiment with fresh sensor noise.",
        "",
        "| θ_r [°] | manual K_p, K_i, K_d (ours) | manual (book) | automatic (ours) | "
        "automatic (book) | experiments (manual / automatic) |",
        "|---|---|---|---|---|---|",
    ]
    for key in ("15", "45", "75"):
        lines.append(
            f"| {key} | {gains(manual[key].gains)} | {gains(BOOK_TABLE_2_2['manual'][key])} | "
            f"{gains(auto[key].result.k)} | {gains(BOOK_TABLE_2_2['auto'][key])} | "
            f"{len(manual[key].trials)} / {auto[key].result.evaluations} |"
        )
    seq, at_90 = auto["sequence"].result, manual[FULL_KEY]
    lines += [
        f"| 90 (Fig. 2.5) | {gains(at_90.gains)} | not printed | — | — | {len(at_90.trials)} / — |",
        f"| 15→45→75→90 (Fig. 2.6a) | — | — | {gains(seq.k)} | "
        f"{gains(BOOK_TABLE_2_2['auto']['sequence'])} | — / {seq.evaluations} |",
        "",
        _tolerance_text(findings.missed, m.tolerance),
        "",
        f"Ziegler-Nichols at 90° (the option of `tuning/manual.py`): ultimate gain "
        f"K_u = {zn.ku:.3g} counts/°, period T_u = {zn.tu:.3g} s, so the classic table "
        f"gives PI {gains(zn.pi)} and PID {gains(zn.pid)}: a PID K_p "
        f"{findings.zn_kp_ratio:.3g} times the scripted procedure's at 90° "
        f"({at_90.gains[0]:.3g}), with K_d = {zn.pid[2]:.3g} where the procedure "
        f"kept {at_90.gains[2]:g}.",
        "",
        "![Fig. 2.5](ch2/fig2_5.png)",
        "",
        "![Fig. 2.6](ch2/fig2_6.png)",
        "",
    ]
    return lines


def _tolerance_text(missed: tuple[str, ...], tolerance: float) -> str:
    """Whether every manual run's K_i ladder met the steady-state tolerance [°]."""
    if not missed:
        return f"Every manual run reached a steady-state error within {tolerance:g}°."
    return (
        f"The manual K_i ladder did not bring the steady-state error within {tolerance:g}° at "
        + ", ".join(f"{k}°" for k in missed)
        + "; the largest K_i tried is kept there."
    )


def _comparison_lines(comparison: Comparison, findings: Findings) -> list[str]:
    """Table 2.3 ours beside the book's, the notes on it, Figs. 2.7-2.10."""
    c = comparison
    lines = [
        "### Comparison (Sect. 2.4.2.2): Table 2.3, Figs. 2.7-2.10",
        "",
        f"Six controllers × {len(FREQUENCIES)} frequencies × {c.trials} trials, each trial with "
        "its own seed for the sensor noise and for the actuator's variation (pressure, fill "
        f"time, reach ±{100 * c.trial_spread:g} % σ), run as `articula sweep ch2/{SWEEP}.toml "
        "--out DIR` (the sweep file with the tuned gains is written beside this report). "
        f"Reference θ_r = {c.offset_deg:g}° − {c.amplitude_deg:g}°·cos(2πft), from rest, two "
        "periods and at least 10 s; E (2.7) over every sample, on the sensor reading as in the "
        "book. Ordinary PID: manual gains tuned at 90° (Fig. 2.5), automatic gains tuned on the "
        "whole-range sequence (Fig. 2.6a). Cells: ours median (Q1, Q3) / book median.",
        "",
        "| f [Hz] | " + " | ".join(CONTROLLERS) + " |",
        "|---|" + "---|" * len(CONTROLLERS),
    ]
    for i, f in enumerate(FREQUENCIES):
        cells = []
        for n in CONTROLLERS:
            med, q1, q3 = c.table[n][f]
            mark = "**" if med == findings.lowest[f] else ""
            cells.append(
                f"{mark}{fixed(med, 2)}{mark} ({fixed(q1, 2)}, {fixed(q3, 2)}) / "
                f"{fixed(BOOK_TABLE_2_3[n][i][0], 2)}"
            )
        lines.append(f"| {f:g} | " + " | ".join(cells) + " |")
    fits = ", ".join(
        f"{f:g} Hz: {ratio:.2f}, {math.degrees(lag):.0f}°"
        for f, (ratio, lag) in findings.calibration.items()
    )
    lines += [
        "",
        "Bold: the lowest median at that frequency. "
        + _misprint_text(findings.misprints)
        + " "
        + _still_text(findings.still, findings.spans),
        "",
        f"Calibration check (Sect. 2.4.2.2: {TRACKING_LIMIT}): amplitude ratio and lag of the "
        "sensor reading against the reference, fitted at the reference frequency, "
        f"fuzzy-automatic, trial 0: {fits}.",
        "",
    ]
    for stem, label in SINUSOID_FIGURES.values():
        lines += [f"![{label}](ch2/{stem}.png)", ""]
    return [*lines, "![Fig. 2.10](ch2/fig2_10.png)", ""]


def _misprint_text(misprints: tuple[Misprint, ...]) -> str:
    """The book entries whose printed quartiles do not bracket the median."""
    if not misprints:
        return "Every book entry has Q1 ≤ median ≤ Q3."
    bad = "; ".join(
        f"{p.controller} at {p.frequency:g} Hz (median {p.row[0]:.2f}, Q1 {p.row[1]:.2f}, "
        f"Q3 {p.row[2]:.2f})"
        for p in misprints
    )
    return (
        f"The book's quartiles do not bracket the median for {bad}: probably a misprint, "
        "copied as printed (Fig. 2.10 marks it)."
    )


def _still_text(still: float, spans: tuple[Span, ...]) -> str:
    """Our and the book's high-frequency medians against a still actuator's E [°]."""
    parts = "; ".join(
        f"at {s.frequency:g} Hz ours span {s.ours[0]:.1f}-{s.ours[1]:.1f}° and the book's "
        f"{s.book[0]:.1f}-{s.book[1]:.1f}° ({s.book_above_still} of {s.book_count} book "
        f"medians above {still:.1f}°)"
        for s in spans
    )
    text = (
        f"An actuator that stays still at the offset scores E = 2A/π = {still:.1f}° on our "
        f"reference; {parts}."
    )
    if any(s.book_above_still for s in spans):
        text += (
            " A median above that is worse than not moving, which is possible if the book's "
            "reference had another offset or amplitude, or its actuator did not rest at the "
            "reference's mean; the book gives neither offset nor amplitude, so we cannot tell."
        )
    return text


def _kd_lines(tuning: Tuning, findings: Findings) -> list[str]:
    """The K_d probe table, the descents' K_d and the manual procedure's."""
    band = tuning.config.manual.band
    rows = []
    for name, s in findings.kd.items():
        cells = [
            f"{m:.2f} ({w:g}{'; ' + str(c) + ' sustained' if c else ''})"
            for m, w, c in zip(s.mean_cost, s.median_swings, s.sustained, strict=True)
        ]
        v = s.verdict
        rows.append(
            f"| {name} | " + " | ".join(cells) + f" | {v.lowest:g} | "
            f"{_kd_list(v.better)} | {_kd_list(v.worse)} |"
        )
    descent = "; ".join(
        f"{key}: {d.start:.3g} → {d.final:.3g}"
        + ("" if d.moved else " (never moved)")
        + f", step dK_d {d.step_start:.3g} → {d.step_final:.3g}"
        for key, d in findings.descent.items()
    )
    ended = sum(d.final > 0 for d in findings.descent.values())
    stuck = sum(not d.moved for d in findings.descent.values())
    manual = "; ".join(
        f"{key}°: tried {_kd_list(tried)}, kept {tuning.manual[key].gains[2]:g}"
        for key, tried in findings.manual_kd.items()
    )
    return [
        "### Is K_d = 0 optimal? (Sect. 2.4.2.1)",
        "",
        f"Every tuned gain set with its K_d replaced. Cells: mean M (2.5) over {KD_PROBE_SEEDS} "
        "step experiments (the same noise for every K_d), and in brackets the median number of "
        f"swings beyond the {band:g}° band about the levels (and how many of the "
        "experiments swing without dying out). A K_d > 0 is better if it lowers M by more than "
        f"{NOISE_ERRORS:g} standard errors of the paired differences, worse if it raises M by "
        "as much or swings without dying out in most experiments. The claim counts as "
        "reproduced only if for every set no K_d > 0 is better and some K_d > 0 is worse; not "
        "reproduced if some K_d > 0 is better for some set; inconclusive otherwise.",
        "",
        "| gain set | "
        + " | ".join(f"K_d = {kd:g}" for kd in KD_PROBE)
        + " | lowest mean M at K_d | better | worse |",
        "|---|" + "---|" * len(KD_PROBE) + "---|---|---|",
        *rows,
        "",
        f"Coordinate descent's K_d, random start → final: {descent}. {ended} of "
        f"{len(findings.descent)} runs ended at K_d > 0 (the book's ended at 0) and {stuck} "
        "never moved K_d; the descent probes K_d only at ±dK_d about its current value, with a "
        "step that shrinks after every failure, so where it ends is not evidence for or "
        "against the claim (the probe above is).",
        "",
        f"Manual procedure (always tries the first K_d rung): {manual}.",
    ]
