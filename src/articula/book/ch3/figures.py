"""Chapter 3 figures: deactuation against δ (Fig. 3.7), pulse timing map, best pulse."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from articula.book.figures import save

Curve = tuple[np.ndarray, np.ndarray]


def delta_study(
    curves: Mapping[float, Curve],
    delta: Sequence[float],
    peak_deg: Sequence[float],
    settling_s: Sequence[float],
    book: Mapping[float, tuple[float, float]],
    path: Path,
) -> None:
    """Fig. 3.7: bending angle after deactuation for each δ, and peak and settling against δ."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    ax = axes[0]
    colours = plt.cm.viridis(np.linspace(0, 0.9, len(curves)))
    for colour, (d, (t, angle)) in zip(colours, sorted(curves.items()), strict=True):
        ax.plot(t, angle, color=colour, lw=1, label=f"δ = {d:g}")
    ax.axhspan(-1, 1, color="grey", alpha=0.2, lw=0, label="±1° band")
    ax.set_xlabel("time after deactuation [s]")
    ax.set_ylabel("bending angle (orientation sensor) [°]")
    ax.legend(fontsize=7, ncols=2)
    for ax, values, label, col in (
        (axes[1], peak_deg, "peak past rest [°]", 0),
        (axes[2], settling_s, "settling time to ±1° [s]", 1),
    ):
        ax.plot(delta, values, "o-", label="simulated")
        ax.plot(list(book), [v[col] for v in book.values()], "r*", ms=12, label="book (Sect. 3.4)")
        ax.set_xlabel("damping actuation ratio δ, Eq. (3.4)")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=8)
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.suptitle("Fig. 3.7: deactuation of one chamber with the opposite chamber pulsed at δ")
    save(fig, path)


def timing_map(
    starts: np.ndarray, lengths: np.ndarray, settling: np.ndarray, delta: float, path: Path
) -> None:
    """Settling time [s] over the opposite pulse's start and length (rows: length)."""
    fig, ax = plt.subplots(figsize=(7, 4.2))
    x, y = _edges(starts), _edges(lengths)
    image = ax.pcolormesh(x, y, settling, cmap="viridis_r", shading="flat")
    fig.colorbar(image, ax=ax, label="settling time to ±1° [s]")
    ax.set_xlabel("pulse start after the deactuation command [s]")
    ax.set_ylabel("pulse length: fill, hold, until venting [s]")
    ax.set_title(f"Opposite-chamber pulse timing at δ = {delta:g}")
    save(fig, path)


def best_pulse(curves: Mapping[str, Curve], pressures: Mapping[str, Curve], path: Path) -> None:
    """Bending angle and the opposite chamber's pressure for named policies."""
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for label, (t, angle) in curves.items():
        axes[0].plot(t, angle, lw=1, label=label)
    axes[0].axhspan(-1, 1, color="grey", alpha=0.2, lw=0)
    axes[0].set_ylabel("bending angle [°]")
    axes[0].legend(fontsize=8)
    for label, (t, kpa) in pressures.items():
        axes[1].plot(t, kpa, lw=1, label=label)
    axes[1].set_ylabel("opposite chamber gauge pressure [kPa]")
    axes[1].set_xlabel("time after deactuation [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[0].set_title("Deactuation with the opposite-chamber pulse found by coordinate descent")
    save(fig, path)


def _edges(centres: np.ndarray) -> np.ndarray:
    """Cell edges around sorted, evenly or unevenly spaced centres."""
    c = np.asarray(centres, dtype=float)
    if c.size == 1:
        return np.array([c[0] - 0.5, c[0] + 0.5])
    mid = (c[1:] + c[:-1]) / 2
    return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])
