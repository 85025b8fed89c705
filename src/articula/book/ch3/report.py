"""Chapter 3's report section: the model, Fig. 3.7 and the what-ifs as markdown; no computing.

The longer explanations beyond the book (mechanism, stiffening, searches, any direction) are
in `report_beyond`.
"""

from __future__ import annotations

import math

from articula.book.ch3 import report_beyond
from articula.book.ch3.analysis import SOLENOID_S, Findings
from articula.book.ch3.book_values import BOOK_PEAK_DEG, BOOK_SETTLING_S, BOOK_TEXT
from articula.book.ch3.study import Ch3Results, DeltaSweep
from articula.book.ch3.what_ifs import ActuatorModel, ValveCase
from articula.book.text import fixed
from articula.plants.six_chamber import DATASHEET_MODULUS


def markdown(r: Ch3Results, f: Findings) -> str:
    """The section: model and calibration, Fig. 3.7, and the studies beyond the book."""
    lines = _model(r.model, f) + _sensitivity(r.model, r.sensitivity, f.sensitivity_holds)
    lines += _delta(r.delta, f.too_fast)
    lines += report_beyond.lines(r, f)
    return "\n".join(lines)


def _model(m: ActuatorModel, f: Findings) -> list[str]:
    """The constants of the actuator model, where each comes from, and the calibration."""
    p, wn, free = m.params, m.natural_frequency, m.undamped
    rows = [
        ("silicone volume V [cm³]", "geometry (Sect. 3.2.1)", f"{p.volume * 1e6:.1f}"),
        ("k of ε = kθ (radius of gyration / L)", "geometry", f"{p.strain_per_angle:.4f}"),
        ("V E c = A_c r_p L_c/L [cm³/rad]", "geometry", f"{p.lever * 1e6:.3f}"),
        ("c of ε = cP [1/MPa]", "geometry and E", f"{p.strain_per_pressure * 1e6:.3f}"),
        ("I [kg·m²]", "geometry, density, 20 g sensor", f"{p.inertia:.3e}"),
        (
            "E [kPa]",
            "**calibrated**",
            f"{p.youngs_modulus / 1e3:.2f} (datasheet 100 % modulus {DATASHEET_MODULUS / 1e3:.0f})",
        ),
        ("b [N·m·s/rad]", "**calibrated**", f"{p.damping:.3e}"),
        ("V E k² [N·m/rad]", "from E", f"{p.stiffness:.4f}"),
        (
            "ω_n, ζ of the body alone",
            "from the above",
            f"{wn:.2f} rad/s ({wn / 2 / math.pi:.2f} Hz), {m.damping_ratio:.3f}",
        ),
        ("supply pressure [kPa]", "assumed", f"{p.supply / 1e3:.0f}"),
        (
            "valve orifice diameter [mm], C_d",
            "assumed",
            f"{p.orifice_diameter * 1e3:g}, {p.discharge:g}",
        ),
        ("orifice flow_transition [Pa]", "assumed (regulariser)", f"{p.flow_transition:g}"),
        (
            "valve open time to 50 % / 90 % of supply [ms]",
            "orifice model",
            f"{1e3 * m.fill_half_s:.1f} / {1e3 * m.fill_90_s:.1f}",
        ),
    ]
    return [
        "### The actuator model and its calibration (Sect. 3.2.2, Figs. 3.2 and 3.7)",
        "",
        "The book gives none of E, k, c, b or I. Geometry gives k, c (through V E c = "
        "A_c r_p L_c/L, the chamber's pressure force at its lever arm, over the part L_c/L of "
        "the body the chamber spans) and I (constant-curvature bending); E "
        "and b are fitted so that an undamped deactuation of one chamber at the supply pressure "
        f"swings {BOOK_PEAK_DEG:g}° past rest and settles to ±1° in {BOOK_SETTLING_S:g} s "
        "(`articula.book.ch3.calibration.calibrate`, true angle, δ = 0).",
        "",
        "| quantity | source | value |",
        "|---|---|---|",
        *[f"| {a} | {b} | {c} |" for a, b, c in rows],
        "",
        f"Undamped deactuation with these constants: bent {free.bend_deg:.1f}° "
        f"before venting, {free.peak_deg:.2f}° past rest (book: about 18-20°), "
        f"settled in {free.settling_s:.3f} s (book: about 0.9-1 s). **Differs** from "
        f"the material: the calibrated E is {f.modulus_fraction:.1%} of the "
        "Dragon Skin 30 datasheet modulus. A solid beam of datasheet modulus would need about "
        f"{f.datasheet_pressure / 1e6:.1f} MPa in one chamber for the "
        "same bend, far above what a silicone chamber holds, so the real body is much softer in "
        "bending than the beam model of Sect. 3.2.2 with the datasheet E (the book's model gives "
        "no way to say why; the E here is an effective modulus).",
        "",
    ]


def _sensitivity(m: ActuatorModel, cases: tuple[ValveCase, ...], holds: bool) -> list[str]:
    """How much the two assumed valve constants move the fit and the verdict."""
    p = m.params
    rows = [
        f"| {c.label} | {c.free.peak_deg:.2f}° / {fixed(c.free.settling_s, 3)} s | "
        f"{c.pulse.peak_deg:.2f}° / {fixed(c.pulse.settling_s, 3)} s |"
        for c in cases
    ]
    return [
        "The fit depends on two assumed valve constants more than on anything the book gives. "
        "The orifice sets how fast the deactuated chamber vents, and so how hard the release "
        "is; flow_transition is the pressure difference below which the orifice law turns "
        "linear. It stands for the laminar conductance of the valve's passages at small "
        "pressure differences, but its value is not measured: treat it as a numerical "
        "regulariser (the sharp-edged law has an infinite slope at zero difference). Each row "
        "changes one constant from the defaults "
        f"({p.orifice_diameter * 1e3:g} mm, {p.flow_transition:g} Pa), E and b not re-fitted "
        "(true angle):",
        "",
        "| changed constant | δ = 0: peak / settling | book pulse δ = 0.5 |",
        "|---|---|---|",
        *rows,
        "",
        "With other values E and b would be fitted differently; the calibrated E and b are "
        "only as good as these two assumptions. "
        + (
            "Across this range the book's pulse never gives about 2° and 0.5 s, so the "
            "verdict below does not depend on them."
            if holds
            else "For some of these values the book's pulse does give about 2° and 0.5 s, so "
            "the verdict below depends on them."
        ),
        "",
    ]


def _delta(sweep: DeltaSweep, too_fast: list[bool]) -> list[str]:
    """Fig. 3.7: the table of the δ sweep against the book, and the figure."""
    lines = [
        "### Fig. 3.7: deactuation against the damping actuation ratio δ (Eq. 3.4)",
        "",
        "Chamber 0 is filled from the pump, held 1.5 s and vented; at the vent command the "
        "opposite chamber's fill valve opens for the time that brings it to δ times the "
        "deactuation pressure, then vents (the book's brief pulse). Angles are the orientation "
        "sensor's (100 Hz, 0.1° noise). Run as `articula sweep ch3/delta_sweep.toml --out DIR` "
        f"({len(sweep.delta)} runs; the file is copied beside this report).",
        "",
        "| δ | pulse open time [ms] | peak past rest [°] | overshoot [%] | settling to ±1° [s] "
        "| book peak [°] | book settling [s] |",
        "|---|---|---|---|---|---|---|",
    ]
    columns = (
        sweep.delta,
        sweep.open_s,
        sweep.peak_deg,
        sweep.overshoot_pct,
        sweep.settling_s,
        too_fast,
    )
    for d, t_open, pk, ov, st, fast in zip(*columns, strict=True):
        book_peak, book_settling = BOOK_TEXT.get(d, ("—", "—"))
        lines.append(
            f"| {d:g} | {1e3 * t_open:.1f}{' †' if fast else ''} | {fixed(pk, 2)} | "
            f"{fixed(ov, 1)} | {fixed(st, 3)} | {book_peak} | {book_settling} |"
        )
    return [
        *lines,
        "",
        f"† Open time below {1e3 * SOLENOID_S:.0f} ms: shorter than a typical solenoid valve's "
        "5-20 ms switching time, so a real 3/3 valve could not deliver that δ as an open time "
        "(the simulation opens and closes its valves instantly).",
        "",
        "![Fig. 3.7](ch3/fig3_7.png)",
        "",
    ]
