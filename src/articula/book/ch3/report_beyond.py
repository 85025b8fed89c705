"""Chapter 3's report beyond Fig. 3.7 as markdown: why the book's pulse fails, which pulse works.

Sections: the mechanism and a stiffening body, the pulse-timing grid, the searches and damping
in any direction. Formatting only; the numbers come from the study and `analysis.findings`.
"""

from __future__ import annotations

from articula.book.ch3.analysis import Findings
from articula.book.ch3.searches import SIDE_DEG, Directions, Pulse, PulseKind
from articula.book.ch3.study import Ch3Results
from articula.book.ch3.what_ifs import StiffeningRow
from articula.book.text import fixed

SEARCHES = {"book_timing": "δ only, book timing", "timed": "δ, start, length"}
PULSES: dict[PulseKind, str] = {
    "none": "none",
    "side 0": "timed pulse found for side 0°",
    "own": f"timed pulse found for side {SIDE_DEG:g}°",
}


def lines(r: Ch3Results, f: Findings) -> list[str]:
    """The sections after Fig. 3.7, in the report's order."""
    return [
        *_mechanism(r, f),
        *_stiffening(r.stiffening, f.stiffening_helps),
        *_timing(r, f),
        *_search(r.book_timing, r.timed, r.iterations, r.full),
        *_directions(r.directions, f.similar),
    ]


def _mechanism(r: Ch3Results, f: Findings) -> list[str]:
    """Why the opposite chamber cannot brake the first swing, and what damps instead."""
    m, sweep, mech = r.model, r.delta, r.mechanism
    free, pulsed = mech.free, mech.pulsed
    p = m.params
    return [
        "### What the opposite chamber can do (Sect. 3.2.4, Fig. 3.5)",
        "",
        "The book's explanation does not agree with its own bending rule. A pressurised chamber "
        "bends the body away from itself, so the chamber opposite the one being vented pushes "
        "the body toward rest and beyond: the same way as the return swing, not against it. "
        "With forces that superpose linearly and pressures that switch at once (the book's "
        "linear model with instant pressures), the opposite pulse adds a step −δP at the vent "
        "command and +δP when it ends; the residual swing of an undamped body is then "
        "|−(1 + δ) + δ e^{iωt_p}| ≥ 1 times the undamped one for any pulse length t_p: in that "
        "model such a pulse cannot reduce the oscillation. A pulse that starts half a period "
        "after the vent command and lasts half a period leaves |−1 + 2δ|, zero at δ = 0.5: it "
        "brakes the second swing, not the first.",
        "",
        "The simulated pneumatics do a little better than that bound at small δ: the sensor's "
        f"peak falls from {fixed(sweep.peak_deg[0], 2)}° at δ = 0 to "
        f"{fixed(sweep.peak_deg[sweep.delta.index(mech.delta)], 2)}° at δ = {mech.delta:g} "
        f"({100 * f.reduction:.0f} % less; true angle {free.peak_deg:.2f}° → "
        f"{pulsed.peak_deg:.2f}°). The cause is the deactuated chamber, not the opposite one: "
        f"chamber 0 takes {1e3 * free.vented_s:.0f} ms to vent to 5 % of supply, about "
        f"{free.vented_s / f.period_s:.2f} of the body's {f.period_s:.3f} s period, and the "
        f"pulse speeds the return (rest reached after {1e3 * pulsed.rest_s:.0f} ms instead of "
        f"{1e3 * free.rest_s:.0f} ms), so chamber 0 is compressed while it is still "
        f"venting and pushes back harder (mean gauge until rest {pulsed.p0_mean / 1e3:.1f} "
        f"kPa instead of {free.p0_mean / 1e3:.1f} kPa). That is a few per cent, far from the "
        "book's about 2° and 0.5 s.",
        "",
        "What else acts in a real actuator, and is modelled here: each chamber's air is a gas "
        "(polytropic n = 1.2) whose volume changes with the bend (V_i = V_0 + a_i·β); a chamber "
        "whose valve holds is a gas spring, and air pushed through an open valve's orifice "
        "loses energy, a pneumatic damper. Six sealed chambers at atmospheric pressure would "
        f"add {m.gas_stiffness_atm:.3f} N·m/rad (at δ = 0.5 of supply "
        f"{m.gas_stiffness_half:.3f} N·m/rad) to the body's {p.stiffness:.3f}, but a chamber "
        "holds only during a pulse; vented chambers leak that spring through their orifices "
        "and damp instead. The overshoot splits into two effects: the body's own damping "
        f"(ζ = {m.damping_ratio:.3f}) would leave {100 * f.body_overshoot:.0f} %; the same bend "
        "released with every chamber already at atmosphere (air flowing through the orifices) "
        f"overshoots {100 * mech.vented_overshoot:.0f} %; the deactuation, in which chamber 0 "
        f"vents through its orifice while the body returns, overshoots {100 * free.overshoot:.0f}"
        " % (b was calibrated with the pneumatics in place). The slow vent of the deactuated "
        "chamber does most of that damping. Not modelled: valve switching delays (5-20 ms for "
        "solenoid valves; equal for every valve they would only shift a long response, but "
        "they are as long as the pulses' open times, see † above), choked flow and heat "
        "exchange.",
        "",
        _verdict(r, f),
        "",
    ]


def _verdict(r: Ch3Results, f: Findings) -> str:
    """What the sweep of the book's pulse shows, in words decided by its numbers."""
    peak, settle, delta = r.delta.peak_deg, r.delta.settling_s, r.delta.delta
    if f.grows:
        verdict = "**Agrees** with the book: the opposite pulse damps."
    else:
        shortest, longest = f.open_ms or (0.0, 0.0)
        verdict = (
            "**Differs** from the book: a pulse at the vent command, vented once filled, "
            f"lasts only the valve's fill time ({shortest:.0f}-{longest:.0f} ms against a "
            f"period of {f.period_s:.3f} s) and barely changes the swing; held longer it pushes "
            "the body further past rest (next section)."
        )
    return (
        f"**Result:** with the book's timing the peak goes from {fixed(peak[0], 2)}° at δ = 0 "
        f"to {fixed(peak[-1], 2)}° at δ = {delta[-1]:g} and the settling time from "
        f"{fixed(settle[0], 3)} s to {fixed(settle[-1], 3)} s (shortest "
        f"{fixed(settle[f.fastest], 3)} s at δ = {delta[f.fastest]:g}). {verdict}"
    )


def _stiffening(rows: tuple[StiffeningRow, ...], helps: bool) -> list[str]:
    """Would a body that stiffens with chamber pressure let the book's pulse damp?"""
    table = [
        f"| {row.stiffening:g} | "
        + " | ".join(f"{o.peak_deg:.2f}° / {fixed(o.settling_s, 3)} s" for o in row.outcomes)
        + " |"
        for row in rows
    ]
    return [
        "A body that stiffens with pressure is the other mechanism the chapter could rely on; "
        "the book gives no data, so the model has it off (`stiffening = 0`). With V E k² raised "
        "by s for each chamber at full supply (E and b not re-fitted, so compare within a row):",
        "",
        "| s | no pulse: peak / settling | book pulse δ = 0.5 | δ = 0.5 held 0.1 s |",
        "|---|---|---|---|",
        *table,
        "",
        "This stiffening is a phenomenological term with no energy source: a stiffness that "
        "changes with pressure while the body is bent adds or removes elastic energy that no "
        "work term accounts for, so the rows are only a qualitative what-if. Within it, "
        "stiffening "
        + (
            "lets the pulse at the vent command halve the peak for some s."
            if helps
            else "does not let the pulse at the vent command halve the peak for any s tried: "
            "the inflated opposite chamber still pushes the way the body swings."
        ),
        "",
    ]


def _timing(r: Ch3Results, f: Findings) -> list[str]:
    """The pulse-timing grid: its map and its notable pulses."""
    t = r.timing
    s = f.timing
    free = r.model.undamped
    return [
        "### Which timing of the opposite pulse damps",
        "",
        "Settling time (true angle) over the pulse's start after the vent command and its "
        f"length (fill, then hold, then vent), at δ = {t.delta:g}: "
        "`articula sweep ch3/timing_sweep.toml --out DIR` "
        f"({t.start.size} runs). Undamped: {free.settling_s:.3f} s, "
        f"{free.peak_deg:.2f}° past rest; the body's period is {f.period_s:.3f} s.",
        "",
        "![pulse timing](ch3/timing.png)",
        "",
        f"- Shortest settling on the grid: start {t.start[s.best]:.3f} s, length "
        f"{t.length[s.best]:.3f} s: {t.settling_s[s.best]:.3f} s with {t.peak_deg[s.best]:.2f}° "
        "past rest.",
        f"- Shortest settling among pulses that do not raise the first swing: start "
        f"{t.start[s.calm]:.3f} s, length {t.length[s.calm]:.3f} s: {t.settling_s[s.calm]:.3f} s "
        f"with {t.peak_deg[s.calm]:.2f}°.",
        f"- The book's timing held longer (start {t.start[s.early]:g} s, length "
        f"{t.length[s.early]:g} s): {fixed(float(t.settling_s[s.early]), 3)} s with "
        f"{float(t.peak_deg[s.early]):.2f}° past rest.",
        f"- Lowest first swing on the grid: {s.lowest_peak_deg:.2f}° (undamped "
        f"{free.peak_deg:.2f}°).",
        "",
    ]


def _search(book_timing: Pulse, timed: Pulse, iterations: int, full: bool) -> list[str]:
    """The two coordinate-descent searches and the figure of their pulses."""
    rows = []
    for pulse, label in ((book_timing, SEARCHES["book_timing"]), (timed, SEARCHES["timed"])):
        k = pulse.policy
        rows.append(
            f"| {label} | {k.delta:.3f} | {k.start:.3f} | {k.length:.3f} | "
            f"{pulse.settling_s:.3f} | {fixed(pulse.peak_deg, 2)} | {pulse.evaluations} |"
        )
    return [
        "### Beyond the book: the δ and pulse timing that minimise settling time",
        "",
        "Chapter 2's coordinate descent (Algorithm 1, `articula.tuning.coordinate_descent`) on "
        "the simulated settling time of the true angle, from fixed starting points "
        f"({'full' if full else 'quick'} mode: at most {iterations} sweeps).",
        "",
        "| search | δ | start [s] | length [s] | settling [s] | peak past rest [°] | evaluations |",
        "|---|---|---|---|---|---|---|",
        *rows,
        "",
        "![best pulse](ch3/search.png)",
        "",
    ]


def _directions(d: Directions, similar: bool) -> list[str]:
    """The side-0° pulse on other sides, and the pulse found for a side between chambers."""
    rows = [
        f"| {row.side_deg:g} | {PULSES[row.pulse]} | {row.outcome.bend_deg:.2f} | "
        f"{row.outcome.peak_deg:.2f} | {fixed(row.outcome.settling_s, 3)} |"
        for row in d.rows
    ]
    own = d.own.policy
    return [
        "### Beyond the book: damping in any bending direction",
        "",
        "A side between two chambers is pressurised by the two nearest chambers "
        "(`control.chamber_allocation.side_pressures`) and the pulse goes to their two "
        "opposite chambers at δ times each one's pressure. The same policy (found above for "
        "chamber 0) applied to other sides:",
        "",
        "| pressurised side [°] | pulse | bend before venting [°] | peak past rest [°] | "
        "settling [s] |",
        "|---|---|---|---|---|",
        *rows,
        "",
        "Sides 0° and 60° give the same numbers (the six-fold symmetry, tested). Between "
        "chambers the two nearest chambers are each regulated to their share of the side's "
        "pressure (fill below it, vent above it, until the vent command), so at rest they push "
        "as one chamber at full supply and the bend before venting is nearly the same; the "
        "deactuation pressure of Eq. (3.4) is then the pressure they hold. What differs is the "
        "release: two chambers at part pressure, each venting through its own orifice, empty "
        "on a different time course than one chamber at full supply, so the timing found for "
        f"chamber 0 {'does about as well' if similar else 'settles more slowly'} between "
        f"chambers. A search for side {SIDE_DEG:g}° (same descent, started from the side-0° pulse) "
        f"finds δ = {own.delta:.3f}, start {own.start:.3f} s, length {own.length:.3f} s: "
        f"settling {d.own.settling_s:.3f} s.",
        "",
    ]
