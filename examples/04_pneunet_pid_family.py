"""PID, piecewise PID and fuzzy PID tracking a sinusoid on the simulated PneuNet (chapter 2).

The three controllers of Sect. 2.3.1 share one discrete PID, u[n] = K(θ_r)ᵀ E[n] (Eqs. 2.2-2.4);
they differ only in the gain schedule K(θ_r): constant, piecewise constant on the subranges
[0, 30), [30, 60), [60, 90] °, or piecewise linear between their midpoints (Fig. 2.2). The
gains are the book's automatically tuned ones (Table 2.2). Each controller tracks
θ_r = 45° − 45° cos(2πft) on a batch of actuators that differ as rigs do, and the script prints
E of Eq. (2.7) as Table 2.3 summarises it (median and quartiles over the trials), beside the
book's number, with the RMS and largest error.

    .venv/bin/python examples/04_pneunet_pid_family.py [--frequency 0.5] [--quick] [--out DIR]
"""

import argparse
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from articula.book.ch2.book_values import BOOK_TABLE_2_2, BOOK_TABLE_2_3, FREQUENCIES
from articula.control.pid import PID, GainSchedule
from articula.loops.pneunet_pid import run_closed_loop
from articula.plants.pneunet import PneuNetParams
from articula.tuning.response import tracking_error

POINTS = [15.0, 45.0, 75.0]  # [°] representative points of the three subranges
SUBRANGE_GAINS = [BOOK_TABLE_2_2["auto"][f"{p:g}"] for p in POINTS]  # [K_p, K_i, K_d] each
SCHEDULES = {  # name -> (gain schedule, its row of Table 2.3)
    "PID": (GainSchedule("constant", [BOOK_TABLE_2_2["auto"]["sequence"]]), "ordinary-auto"),
    "piecewise PID": (GainSchedule("piecewise", SUBRANGE_GAINS, POINTS), "piecewise-auto"),
    "fuzzy PID": (GainSchedule("fuzzy", SUBRANGE_GAINS, POINTS), "fuzzy-auto"),
}


def print_row(name, *cells):
    """One line of the printed table: numbers to two decimals, in aligned columns."""
    text = [f"{c:>9.2f}" if isinstance(c, float) else f"{c:>9}" for c in cells]
    print(f"{name:<14}" + "".join(text))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frequency", type=float, default=0.05, choices=FREQUENCIES, help="[Hz]")
    parser.add_argument("--quick", action="store_true", help="5 trials instead of 25")
    parser.add_argument("--out", type=Path, default=Path("example_output/04_pneunet_pid_family"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    params = PneuNetParams()  # the simulated actuator, 30 Hz valve PWM (Sect. 2.4.1.2)
    trials = 5 if args.quick else 25
    duration = max(2 / args.frequency, 10.0)  # [s] two periods, at least 10 s, as in Table 2.3
    t = np.arange(round(duration / params.pwm_period)) * params.pwm_period
    reference = 45.0 - 45.0 * np.cos(2 * np.pi * args.frequency * t)  # [°], starts at rest
    column = FREQUENCIES.index(args.frequency)

    print(f"θ_r = 45° − 45° cos(2π·{args.frequency:g} Hz·t), {duration:g} s, {trials} trials")
    print_row("controller", "E median", "E Q1", "E Q3", "book E", "RMSE", "max |e|")
    traces = {}
    for name, (schedule, book_row) in SCHEDULES.items():
        pid = PID(schedule, output_limits=(0.0, 255.0))  # the valve's 8-bit PWM count
        trace = run_closed_loop(params, pid, reference, seeds=range(trials))
        error = trace.reference - trace.measured  # on the flex sensor, as the book measured
        E = tracking_error(trace.reference, trace.measured)  # Eq. (2.7), one per trial
        q1, median, q3 = np.percentile(E, [25, 50, 75])
        rmse = np.median(np.sqrt(np.mean(error**2, axis=1)))
        worst = np.median(np.max(np.abs(error), axis=1))
        print_row(name, median, q1, q3, BOOK_TABLE_2_3[book_row][column][0], rmse, worst)
        traces[name] = trace
    print("all in degrees; E: Eq. (2.7), mean |θ_r − θ|, on the sensor; book: Table 2.3;")
    print("RMSE and max |e|: medians over the trials")

    fig = Figure(figsize=(9, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
    top.plot(t, reference, color="k", lw=1.5, label="reference θ_r")
    for name, trace in traces.items():
        top.plot(t, trace.measured[0], lw=1.0, label=f"{name} (trial 0)")
        bottom.plot(t, trace.reference - trace.measured[0], lw=0.8, label=name)
    top.set_ylabel("bending angle (sensor) [°]")
    top.set_title(f"PneuNet tracking a {args.frequency:g} Hz sinusoid, book gains (Table 2.2)")
    top.legend(fontsize=8)
    bottom.set_xlabel("time [s]")
    bottom.set_ylabel("error θ_r − θ [°]")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    path = args.out / "responses.png"
    fig.savefig(path, dpi=110)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
