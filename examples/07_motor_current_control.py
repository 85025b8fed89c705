"""DC-motor current (torque) control: the model of Sect. 4.2 and the PI + feed-forward loop.

Part 1, the model of Table 4.2 (the primary motor with the secondary on its shaft): the state
space of Eq. (4.6), its poles, the transfer matrix G(s) of Eq. (4.7) as a python-control object
from inputs [τ_ex, V] to outputs [ω, i], and the steady state of Eq. (4.8), checked against
G(0). Part 2, the closed loop of Sect. 4.4 on the simulated dual-motor rig: a 1 A current step
from rest at ω_ss = 5 rad/s with V = V_bias + K_p e + K_i ∫e (Eqs. 4.13-4.14, K_p = 10,
K_i = 100), the 8-bit PWM of Eqs. (4.15)-(4.16), a noisy ACS712 current sensor and the moving
average of Eq. (4.17) of order k on the fed-back current (Figs. 4.5 and 4.8).

    .venv/bin/python examples/07_motor_current_control.py [--quick] [--out DIR]
"""

import argparse
import os
from pathlib import Path

import control as ct
import numpy as np
from matplotlib.figure import Figure

from articula.experiments.motor import CurrentControlConfig, simulate_batch
from articula.plants import dc_motor

VOLTAGE, TORQUE = 12.0, -0.3  # [V], [N·m]: the supply and an opposing load (Eq. 4.10)
PLOTTED = (1, 50)  # filter orders drawn: unfiltered (Fig. 4.5) and k = 50 (Fig. 4.8)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 s runs, k = 1 and 50 only")
    parser.add_argument("--out", type=Path, default=Path("example_output/07_motor_current_control"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    p = dc_motor.TABLE_4_2
    A, B = dc_motor.state_space(p)
    print(f"Table 4.2: R = {p.R} Ω, K = {p.K} N·m/A, b = {p.b} N·m·s/rad, J = {p.J} kg·m²,")
    print(f"L = {p.L * 1e3:g} mH (not in the book); states [ω, i], inputs [τ_ex, V]")
    print(f"A = {A.round(4).tolist()}, B = {B.tolist()}  (Eq. 4.6)")
    print(f"poles: {np.sort(dc_motor.poles(p).real).round(4).tolist()} 1/s")
    G = dc_motor.transfer_matrix(p)
    names = [["omega/tau_ex", "omega/V"], ["i/tau_ex", "i/V"]]
    tf = ct.tf([[G[n][0] for n in row] for row in names], [[G[n][1] for n in row] for row in names],
               inputs=["tau_ex", "V"], outputs=["omega", "i"], name="G")  # fmt: skip
    print("transfer matrix, Eq. (4.7):", tf)
    omega_ss, i_ss = dc_motor.steady_state(p, VOLTAGE, TORQUE)
    dc = tf.dcgain() @ [TORQUE, VOLTAGE]
    print(f"steady state at V = {VOLTAGE:g} V, τ_ex = {TORQUE:g} N·m, Eq. (4.8): "
          f"ω_ss = {omega_ss:.4f} rad/s, i_ss = {i_ss:.4f} A")  # fmt: skip
    print(f"the same from G(0) @ [τ_ex, V]: ω = {dc[0]:.4f} rad/s, i = {dc[1]:.4f} A")
    omega_c = dc_motor.critical_speed(p, VOLTAGE, 1.0)
    print(f"critical speed for 1 A at {VOLTAGE:g} V (Sect. 4.3.2): ω_c = {omega_c:.4f} rad/s\n")

    duration = 3.0 if args.quick else 6.0  # [s]
    orders = PLOTTED if args.quick else (1, 10, 50)
    print(f"current step 0 → 1 A at 5 rad/s, {duration:g} s; steady state after 2.5 s")
    print(f"{'k':>4}{'rise i':>10}{'rise fed back':>15}{'peak i':>9}{'RMS error':>11}{'noise':>9}")
    runs = {}
    for k in orders:
        config = CurrentControlConfig(duration=duration, settle=2.5, controller={"filter_order": k})
        channels, m = simulate_batch(config, trials=1)
        run = runs[k] = {name: values[0] for name, values in channels.items()}
        values = (k, m["rise_time"][0], m["rise_time_feedback"][0], run["i"].max(),
                  m["current_rms_error"][0], m["noise_rms"][0])  # fmt: skip
        print("{:4d}{:8.3f} s{:13.3f} s{:7.3f} A{:9.4f} A{:7.4f} A".format(*values))
    print("rise: 10-90 % of the true and of the fed-back current; RMS error of the true current")
    print("and noise of the fed-back one (fed-back − the same filter on the truth), after 2.5 s")

    t = np.arange(config.steps) * config.dt
    fig = Figure(figsize=(10, 6), layout="constrained")
    axes = fig.subplots(2, 2, sharex="col", width_ratios=[1, 2])
    for column, shown in enumerate((t <= 0.3, t >= 0)):  # the step, the whole run
        current, voltage = axes[:, column]
        current.plot(t[shown], runs[1]["i_ref"][shown], "k", lw=1.2, label="reference")
        for color, k in enumerate(PLOTTED):
            run = runs[k]
            current.plot(t[shown], run["i_fb"][shown], f"C{color}", lw=0.6, alpha=0.5,
                         label=f"fed back, k = {k}")  # fmt: skip
            current.plot(t[shown], run["i"][shown], f"C{color}", lw=1.4, label=f"true, k = {k}")
            voltage.plot(t[shown], run["v1"][shown], f"C{color}", lw=0.7, label=f"k = {k}")
        current.set_ylabel("primary current [A]")
        voltage.set_ylabel("applied voltage (8-bit PWM) [V]")
        voltage.set_xlabel("time [s]")
        for ax in (current, voltage):
            ax.grid(True, alpha=0.3)
    axes[0, 0].set_title("the step (first 0.3 s)")
    axes[0, 1].set_title("the whole run")
    axes[0, 1].legend(fontsize=8, ncol=2)
    axes[1, 1].legend(fontsize=8)
    path = args.out / "current_step.png"
    fig.savefig(path, dpi=110)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
