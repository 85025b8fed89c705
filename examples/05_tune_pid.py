"""Tune the PneuNet's PID three ways: Ziegler-Nichols, the book's manual rule, coordinate descent.

Every tuner sees only experiments: "run the simulated actuator from rest with gains
K = [K_p, K_i, K_d] and return the sensor's response" (`SimulatedRig`, fresh sensor noise each
call), as it would on a real rig. Ziegler-Nichols raises a P-only gain on a step to 90° until
the swings last (ultimate gain K_u, period T_u) and reads the classic table; the manual
procedure of Sect. 2.3.2.1 raises K_p, then K_i, then K_d, judging each step response; the
coordinate descent of Algorithm 1 (Sect. 2.3.2.2) minimises M(K) of Eq. (2.5) on steps through
15°, 45°, 75° and 90°. The script prints each tuner's gains and experiments, and scores every
gain set the same way: M on that step sequence and E of Eq. (2.7) tracking the 0.05 Hz
sinusoid of Table 2.3 on 25 actuators that differ as rigs do.

    .venv/bin/python examples/05_tune_pid.py [--quick] [--out DIR]
"""

import argparse
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from articula.book.ch2.tuning import step_reference
from articula.control.pid import PID, GainSchedule
from articula.loops.pneunet_pid import SimulatedRig, run_closed_loop
from articula.plants.pneunet import PneuNetParams
from articula.tuning.coordinate_descent import coordinate_descent
from articula.tuning.manual import Ladder, manual_tuning, ultimate_gain, ziegler_nichols
from articula.tuning.response import tracking_error, tuning_cost

LEVELS = (15.0, 45.0, 75.0, 90.0)  # [°] the descent's step sequence (Fig. 2.6a), 4 s each
SCORE_SEED = 99  # every gain set is scored on the same sensor noise


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 sweeps of the descent, not 30")
    parser.add_argument("--out", type=Path, default=Path("example_output/05_tune_pid"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    params = PneuNetParams()
    step_90 = step_reference((90.0,), 10.0, params.pwm_period)  # [°] at every PWM period
    sequence = step_reference(LEVELS, 4.0, params.pwm_period)

    ladder = Ladder(start=0.25, factor=1.25, stop=200.0)  # P-only K_p rungs [counts/°]
    ku, tu, zn_trials = ultimate_gain(SimulatedRig(params, step_90, seed=1), ladder, band=2.0)
    manual = manual_tuning(SimulatedRig(params, step_90, seed=2))

    rig = SimulatedRig(params, sequence, seed=3)

    def cost(k):  # M(K), Eq. (2.5): one experiment on the rig per evaluation
        r = rig(k)
        return float(tuning_cost(r.t, r.reference, r.measured))

    rng = np.random.default_rng(0)  # Algorithm 1 starts from random K and dK
    k0, dk0 = rng.uniform(0, [2.0, 4.0, 0.2]), rng.uniform(0, [0.5, 1.0, 0.1]) + 1e-6
    descent = coordinate_descent(
        cost, k0, dk0, k_stop=0.05, max_iterations=5 if args.quick else 30,
        lower=np.zeros(3), upper=np.array([20.0, 40.0, 5.0]),
    )  # fmt: skip

    tuned = {  # name -> (gains, experiments it took)
        "Ziegler-Nichols PI": (ziegler_nichols(ku, tu, "PI"), len(zn_trials)),
        "Ziegler-Nichols PID": (ziegler_nichols(ku, tu, "PID"), len(zn_trials)),
        "manual (2.3.2.1)": (manual.gains, len(manual.trials)),
        "descent (Alg. 1)": (descent.k, descent.evaluations),
    }
    t = np.arange(round(40.0 / params.pwm_period)) * params.pwm_period
    sinusoid = 45.0 - 45.0 * np.cos(2 * np.pi * 0.05 * t)  # [°]
    print(f"ultimate gain K_u = {ku:.3g} counts/°, period T_u = {tu:.3g} s (step to 90°)")
    print(f"{'tuner':<20}{'K_p':>7}{'K_i':>7}{'K_d':>7}{'runs':>6}{'M steps':>9}{'E sine':>8}")
    responses = {}
    for name, (k, runs) in tuned.items():
        r = responses[name] = SimulatedRig(params, sequence, SCORE_SEED)(k)
        m = tuning_cost(r.t, r.reference, r.measured)
        pid = PID(GainSchedule("constant", [k]), output_limits=(0.0, 255.0))
        trace = run_closed_loop(params, pid, sinusoid, seeds=range(25))
        e = np.median(tracking_error(trace.reference, trace.measured))
        print(f"{name:<20}{k[0]:7.3f}{k[1]:7.3f}{k[2]:7.3f}{runs:6d}{m:9.2f}{e:8.2f}")
    print("gains in PWM counts per °, °·s, °/s; runs: experiments the tuner made;")
    print("M steps: Eq. (2.5) on the 15-45-75-90° steps; E sine: median E (2.7) [°], 0.05 Hz")

    fig = Figure(figsize=(9, 7), layout="constrained")
    top, bottom = fig.subplots(2, 1, height_ratios=[3, 2])
    top.plot(np.arange(sequence.size) * params.pwm_period, sequence, "k", lw=1.5, label="reference")
    for name, r in responses.items():
        top.plot(r.t, r.measured, lw=0.9, label=name)
    top.set_xlabel("time [s]")
    top.set_ylabel("bending angle (sensor) [°]")
    top.set_title("Step responses of the tuned gains (same sensor noise)")
    top.legend(fontsize=8, ncol=2)
    evaluations = [h.evaluations for h in descent.history]
    bottom.step(evaluations, [h.best_cost for h in descent.history], where="post")
    bottom.set_xlabel("experiments on the simulated rig")
    bottom.set_ylabel("best M(K), Eq. (2.5) [° + °/s]")
    bottom.set_title("Coordinate descent (Algorithm 1) converging")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    path = args.out / "tuning.png"
    fig.savefig(path, dpi=110)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
