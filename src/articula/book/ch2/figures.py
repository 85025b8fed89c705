"""Chapter 2 figures: manual-tuning steps, descent convergence, sinusoid trials, error summary."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from articula.book.figures import save
from articula.tuning.coordinate_descent import DescentResult
from articula.tuning.manual import ManualResult


def manual_steps(result: ManualResult, title: str, path: Path) -> None:
    """Fig. 2.5: every step response of the manual procedure, the chosen gains in red."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    chosen = None
    for trial in result.trials:
        r = trial.response
        if np.array_equal(trial.gains, result.gains) and chosen is None:
            chosen = trial
            continue
        ax.plot(r.t, r.measured, lw=0.7, color="0.7")
    ref = result.trials[0].response
    ax.plot(ref.t, ref.reference, color="C0", lw=1.5, label="reference")
    if chosen is not None:
        k = chosen.gains
        ax.plot(
            chosen.response.t,
            chosen.response.measured,
            color="C3",
            lw=1.3,
            label=f"chosen: K_p={k[0]:.3g}, K_i={k[1]:.3g}, K_d={k[2]:.3g}",
        )
    ax.plot([], [], color="0.7", lw=0.7, label="other trials of the procedure")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("bending angle (sensor) [°]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    save(fig, path)


def convergence(runs: Mapping[str, DescentResult], path: Path) -> None:
    """Fig. 2.6: K_p, K_i, K_d and the best M against the number of experiments."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=False)
    for ax, (title, result) in zip(axes.flat, runs.items(), strict=False):
        n = [h.evaluations for h in result.history]
        k = np.array([h.k for h in result.history])
        for j, name in enumerate(("K_p", "K_i", "K_d")):
            ax.step(n, k[:, j], where="post", label=name)
        twin = ax.twinx()
        twin.step(n, [h.best_cost for h in result.history], where="post", color="0.5", ls=":")
        twin.set_ylabel("best M(K), Eq. (2.5)", color="0.4")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("experiments (evaluations of M)")
        ax.set_ylabel("gain")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    save(fig, path)


def sinusoid_trials(traces: Mapping[str, Mapping[str, np.ndarray]], title: str, path: Path) -> None:
    """Figs. 2.7-2.9: one trial per controller against the sinusoidal reference."""
    fig, axes = plt.subplots(2, 3, figsize=(13, 6), sharex=True, sharey=True)
    for ax, (name, tr) in zip(axes.flat, traces.items(), strict=False):
        ax.plot(tr["t"], tr["theta_ref_deg"], color="C0", lw=1.2, label="reference")
        ax.plot(tr["t"], tr["theta_meas_deg"], color="C3", lw=0.8, label="sensor")
        ax.set_title(name, fontsize=9)
        ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    for ax in axes[:, 0]:
        ax.set_ylabel("angle [°]")
    axes[0, 0].legend(fontsize=8, loc="upper right")
    fig.suptitle(title)
    save(fig, path)


def error_summary(
    frequencies: Sequence[float],
    ours: Mapping[str, Sequence[Sequence[float]]],
    book: Mapping[str, Sequence[Sequence[float]]],
    path: Path,
) -> None:
    """Fig. 2.10: median E with first and third quartiles against frequency, ours and book.

    Rows are (median, Q1, Q3). Each bar is drawn from Q1 to Q3 as given, so an entry whose
    quartiles do not bracket the median (the book's fuzzy-automatic 5 Hz Q3) shows as printed
    and is circled and labelled as a probable misprint.
    """
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.5), sharey=True)
    f = np.asarray(frequencies)
    for ax, (label, data) in zip(axes, (("simulated PneuNet", ours), ("book", book)), strict=True):
        for i, (name, rows) in enumerate(data.items()):
            q = np.asarray(rows, dtype=float)
            shift = f * 1.04 ** (i - 2.5)  # spread the markers so the bars do not overlap
            (line,) = ax.plot(shift, q[:, 0], marker="o", ms=3, lw=0.8, label=name)
            ax.vlines(shift, q[:, 1], q[:, 2], color=line.get_color(), lw=0.8)
            ax.plot(shift, q[:, 1], "_", ms=5, color=line.get_color())
            ax.plot(shift, q[:, 2], "_", ms=5, color=line.get_color())
            odd = (q[:, 1] > q[:, 0]) | (q[:, 2] < q[:, 0])
            for x, row in zip(shift[odd], q[odd], strict=True):
                ax.plot(x, row[2], "o", ms=9, mfc="none", color="k", lw=0.8)
                ax.annotate(
                    f"{name}: Q1 {row[1]:g}, Q3 {row[2]:g}, median {row[0]:g} (misprint?)",
                    (x, row[2]),
                    xytext=(-150, -25),
                    textcoords="offset points",
                    fontsize=7,
                    arrowprops={"arrowstyle": "-", "lw": 0.5},
                )
        ax.set_xscale("log")
        ax.set_xlabel("reference frequency [Hz]")
        ax.set_title(f"E, Eq. (2.7): median (Q1, Q3), {label}")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("E [°]")
    axes[0].legend(fontsize=8)
    save(fig, path)
