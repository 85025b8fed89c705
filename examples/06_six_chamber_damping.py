"""Active damping of the six-chamber soft actuator on deactuation (chapter 3, Sects. 3.2.4, 3.4).

Chamber 0 is filled to the supply pressure, held 1.5 s and vented; the body swings back past
rest. The book damps the swing by pulsing the opposite chamber (3) at the vent command to δ
times the vented pressure, δ of Eq. (3.4), and reports (Fig. 3.7) that the peak falls from
about 18° to 2° and settling from 1 s to 0.5 s as δ grows to 0.5. The simulation (body, air in
each chamber, orifice valves, orientation sensor) sweeps the book's pulse over δ and adds a
pulse timed to brake the swing after the first one (src/articula/book/ch3/configs/
timed_pulse.toml). It prints, on the sensor: the first swing past rest, the overshoot, the
settling time to ±1° and the residual oscillation (RMS angle 0.5-2 s after the vent command).

    .venv/bin/python examples/06_six_chamber_damping.py [--quick] [--out DIR]
"""

import argparse
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from articula.control.damping import DampingPolicy
from articula.experiments.six_chamber import DeactuationConfig, run_deactuation

HOLD = 1.5  # [s] chamber 0 filled and held before the vent command
RESIDUAL = (0.5, 2.0)  # [s] after the vent command: the window of the residual RMS
PLOTTED = ("no damping", "book pulse δ=0.5", "timed pulse δ=0.3")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="δ = 0.3 and 0.5 only")
    parser.add_argument("--out", type=Path, default=Path("example_output/06_six_chamber_damping"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    deltas = (0.3, 0.5) if args.quick else (0.1, 0.2, 0.3, 0.4, 0.5, 0.6)
    policies = {"no damping": DampingPolicy()}
    policies |= {f"book pulse δ={d:g}": DampingPolicy(delta=d) for d in deltas}  # at the vent
    policies["timed pulse δ=0.3"] = DampingPolicy(delta=0.3, start=0.15, length=0.045)

    print(f"{'policy':<20}{'peak [°]':>10}{'overshoot':>11}{'settling':>10}{'residual':>10}")
    traces = {}
    for name, policy in policies.items():
        result = run_deactuation(DeactuationConfig(side_deg=0.0, hold=HOLD, damping=policy))
        m, trace = result.metrics, result.trace
        after = trace["t"] - HOLD
        window = (after >= RESIDUAL[0]) & (after <= RESIDUAL[1])
        residual = np.sqrt(np.mean(np.degrees(trace["bend_sensor"][window]) ** 2))
        print(f"{name:<20}{m['peak_deg']:10.2f}{m['overshoot_pct']:10.1f}%"
              f"{m['settling_s']:9.3f}s{residual:9.3f}°")  # fmt: skip
        traces[name] = trace
    print("peak: first swing past rest; overshoot: that swing over the angle at the vent;")
    print("settling: to within ±1° of rest; residual: RMS angle 0.5-2 s after the vent command")

    fig = Figure(figsize=(9, 6.5), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[3, 2])
    runs = traces["no damping"]["t"]  # every run has the same sample times [s]
    shown = runs >= HOLD - 0.2  # from just before the vent command
    t = runs[shown] - HOLD
    for color, name in enumerate(PLOTTED):
        top.plot(t, np.degrees(traces[name]["bend_sensor"][shown]), f"C{color}", label=name)
    vented = traces["no damping"]["p0"][shown] / 1e3  # [kPa]
    bottom.plot(t, vented, "0.4", label="chamber 0 (vented)")
    for color, name in enumerate(PLOTTED[1:], start=1):
        pulse = traces[name]["p3"][shown] / 1e3
        bottom.plot(t, pulse, f"C{color}", label=f"chamber 3, {name}")
    top.axhspan(-1, 1, color="0.85", label="±1° settling band")
    top.set_ylabel("bend angle (sensor) [°]")
    top.set_title("Deactuation of chamber 0 with and without active damping")
    top.legend(fontsize=8)
    bottom.set_xlabel("time after the vent command [s]")
    bottom.set_ylabel("gauge pressure [kPa]")
    bottom.legend(fontsize=8)
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    path = args.out / "damping.png"
    fig.savefig(path, dpi=110)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
