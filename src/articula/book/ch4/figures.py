"""Chapter 4 figures: the current-speed line and the current-control responses."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from articula.book.figures import save


def current_speed_line(
    omega: np.ndarray, current: np.ndarray, omega_c: float, i_c: float, title: str, path: Path
) -> None:
    """Fig. 4.3: quasi-static current against speed at 12 V, with the critical speed marked."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(omega, current, label="i = (V − Kω)/R, Eq. (4.11)")
    ax.axhline(i_c, color="grey", ls=":", lw=1)
    ax.axvline(omega_c, color="C3", ls="--", lw=1, label=f"ω_c = {omega_c:.4f} rad/s at {i_c:g} A")
    ax.set_xlabel("speed ω [rad/s]")
    ax.set_ylabel("current i [A]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    save(fig, path)


def response(trace: Mapping[str, np.ndarray], title: str, path: Path, pwm_bits: int) -> None:
    """Figs. 4.5-4.9: current (measured, fed back, true, reference), speed and PWM duty."""
    t = trace["t"]
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    ax = axes[0]
    ax.plot(t, trace["i_meas"], lw=0.5, color="0.7", label="sensor (raw)")
    if not np.array_equal(trace["i_fb"], trace["i_meas"]):
        ax.plot(t, trace["i_fb"], lw=0.8, color="C1", label="filtered (fed back)")
    ax.plot(t, trace["i"], lw=1.0, color="C0", label="true current")
    ax.plot(t, trace["i_ref"], lw=1.0, color="k", ls="--", label="reference")
    ax.set_ylabel("current [A]")
    ax.legend(loc="lower right", fontsize=8, ncols=2)
    ax = axes[1]
    ax.plot(t, trace["omega_meas"], lw=0.6, color="0.6", label="encoder")
    ax.plot(t, trace["omega"], lw=1.0, color="C2", label="true")
    ax.set_ylabel("speed [rad/s]")
    ax.legend(loc="lower right", fontsize=8)
    ax = axes[2]
    if pwm_bits:
        ax.plot(t, trace["duty1"], lw=0.6, color="C4")
        ax.set_ylabel(f"duty S[n] ({pwm_bits}-bit)")
    else:
        ax.plot(t, trace["v1"], lw=0.6, color="C4")
        ax.set_ylabel("voltage [V]")
    ax.set_xlabel("time [s]")
    for a in axes:
        a.grid(True, alpha=0.3)
    axes[0].set_title(title)
    save(fig, path)


def bandwidth_tradeoff(
    orders: Sequence[int],
    measured: Sequence[float],
    predicted: Sequence[float],
    noise_rms: Sequence[float],
    sweep_curves: Mapping[int, tuple[np.ndarray, np.ndarray]],
    path: Path,
) -> None:
    """Bandwidth against filter order (sweep and linear model) and accuracy against bandwidth."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    ax = axes[0]
    for k, (freq, ratio) in sorted(sweep_curves.items()):
        ax.semilogx(freq, 20 * np.log10(ratio), marker="o", ms=3, label=f"k = {k}")
    ax.axhline(-3, color="grey", ls=":")
    ax.set_xlabel("reference frequency [rad/s]")
    ax.set_ylabel("|i / i_ref| [dB] (simulated sweep)")
    ax.legend(fontsize=8)
    ax = axes[1]
    ax.loglog(orders, measured, "o-", label="simulated frequency sweep")
    ax.loglog(orders, predicted, "s--", label="linearised loop (python-control)")
    ax.set_xlabel("moving-average order k")
    ax.set_ylabel("−3 dB bandwidth [rad/s]")
    ax.legend(fontsize=8)
    ax = axes[2]
    ax.plot(measured, np.asarray(noise_rms) * 1e3, "o-")
    for k, x, y in zip(orders, measured, noise_rms, strict=True):
        ax.annotate(f"k={k}", (x, y * 1e3), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.set_xlabel("−3 dB bandwidth [rad/s]")
    ax.set_ylabel("feedback noise RMS [mA]")
    for a in axes:
        a.grid(True, which="both", alpha=0.3)
    fig.suptitle("Current loop: bandwidth and feedback noise against moving-average order")
    save(fig, path)
