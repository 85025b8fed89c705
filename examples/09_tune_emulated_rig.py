"""Tune the PneuNet's PID on its bench rig over serial, the rig emulated on a pseudo-terminal.

An `Emulator` (what `articula emulate pneunet` starts) runs the rig's device program behind a
pty on a background thread: each PWM period it reads the simulated flex sensor, evaluates the
PID of the gains it was sent (Eqs. 2.2-2.3) and drives the valve, as the book's Arduino does.
The host opens the pty's path with pyserial through `Link` (handshake, acknowledged commands,
losses counted, docs/protocol.md), exactly as it would open /dev/ttyACM0. `PneuNetRig` turns
one experiment on the rig (send gains and a step program, START, collect telemetry) into the
response a tuner needs, and the coordinate descent of chapter 2 (Algorithm 1) minimises M(K)
of Eq. (2.5) with it. Every trial's gains and cost are printed as they come.

    .venv/bin/python examples/09_tune_emulated_rig.py [--quick] [--faults drop=0.01] [--out DIR]

--faults injects line faults (drop, corrupt, delay_ms) on the device's frames; the link counts
them. No AVR toolchain is needed: the device is the Python one.
"""

import argparse
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from articula.book.ch2.tuning import step_reference
from articula.loops.pneunet_pid import SimulatedRig
from articula.rigs.emulator import Emulator, Faults
from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetDevice, PneuNetRig
from articula.rigs.programs import steps
from articula.rigs.protocol import RigKind
from articula.tuning.coordinate_descent import coordinate_descent
from articula.tuning.response import tuning_cost

LEVELS, HOLD = (30.0, 60.0), 4.0  # [°] the step program, [s] per level
SEED = 7  # the emulated rig's sensor noise: experiment n draws from SEED + n


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 sweeps of the descent, not 6")
    parser.add_argument("--faults", default="", help="e.g. drop=0.01,corrupt=0.01")
    parser.add_argument("--out", type=Path, default=Path("example_output/09_tune_emulated_rig"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    device = PneuNetDevice()
    emulator = Emulator(device, faults=Faults.parse(args.faults))
    with emulator, Link(emulator.path, expect=RigKind.PNEUNET) as link:
        info = link.info
        channels = ", ".join(f"{c.name} [{c.unit}]" for c in info.channels)
        print(f"{info.rig.name.lower()} rig on {emulator.path}: a sample every "
              f"{info.sample_period_us} µs of {channels}")  # fmt: skip
        rig = PneuNetRig(link, steps(LEVELS, HOLD), len(LEVELS) * HOLD, SEED)
        trials = []  # (gains, M, response) of every experiment on the rig

        def cost(k):  # M(K) of Eq. (2.5), one experiment on the rig
            response = rig(k)
            m = float(tuning_cost(response.t, response.reference, response.measured))
            trials.append((k, m, response))
            print(f"{len(trials):5d}{k[0]:8.3f}{k[1]:8.3f}{k[2]:8.3f}{m:9.2f}"
                  f"{response.t.size:9d}")  # fmt: skip
            return m

        print(f"{'trial':>5}{'K_p':>8}{'K_i':>8}{'K_d':>8}{'M(K)':>9}{'samples':>9}")
        rng = np.random.default_rng(0)  # Algorithm 1 starts from random K and dK
        k0, dk0 = rng.uniform(0, [2.0, 4.0, 0.2]), rng.uniform(0, [0.5, 1.0, 0.1]) + 1e-6
        result = coordinate_descent(
            cost, k0, dk0, k_stop=0.05, max_iterations=2 if args.quick else 6,
            lower=np.zeros(3), upper=np.array([20.0, 40.0, 5.0]),
        )  # fmt: skip
        stats = link.stats
    k = result.k
    best = next(n for n, trial in enumerate(trials) if np.array_equal(trial[0], k))
    print(f"best: trial {best + 1}, K = {np.round(k, 3).tolist()}, M(K) = {result.cost:.2f}")
    print(f"line: {stats.frames} frames, {stats.crc_errors} damaged, {stats.dropped} lost, "
          f"{stats.resends} commands resent")  # fmt: skip
    reference = step_reference(LEVELS, HOLD, device.params.pwm_period)
    here = SimulatedRig(device.params, reference, SEED + best)(k)  # same actuator and noise
    m = tuning_cost(here.t, here.reference, here.measured)
    print(f"the same experiment in process (loops.pneunet_pid.SimulatedRig): M(K) = {m:.2f}")

    fig = Figure(figsize=(9, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, height_ratios=[3, 2])
    start, best_response = trials[0][2], trials[best][2]
    top.plot(start.t, start.reference, "k", lw=1.5, label="reference (step program)")
    top.plot(start.t, start.measured, "0.6", lw=0.9, label="trial 1: the random start")
    top.plot(best_response.t, best_response.measured, "C3", lw=1.1, label=f"trial {best + 1}: best")
    top.set_xlabel("time on the rig [s]")
    top.set_ylabel("bending angle (sensor) [°]")
    top.set_title("PneuNet rig (emulated), tuned over serial by coordinate descent")
    top.legend(fontsize=8)
    number, costs = np.arange(1, len(trials) + 1), [m for _, m, _ in trials]
    bottom.plot(number, costs, "o", ms=4, label="each trial")
    bottom.step(number, np.minimum.accumulate(costs), "C3", where="post", label="best so far")
    bottom.set_xlabel("trial (experiment on the rig)")
    bottom.set_ylabel("M(K), Eq. (2.5) [° + °/s]")
    bottom.legend(fontsize=8)
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    path = args.out / "rig_tuning.png"
    fig.savefig(path, dpi=110)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
