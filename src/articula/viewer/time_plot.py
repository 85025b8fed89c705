"""A run's series against time as a uPlot in the viewer's panel, with a cursor at the scene's
time: a vertical line drawn as a second series on its own 0-1 scale, its two points at the
cursor's time (uPlot's x values may repeat, so the line is vertical). The series is thinned
to at most MAX_POINTS, each bucket keeping its least and largest value (the plot is a few
hundred pixels wide; every peak stays), so moving the cursor resends little."""

from __future__ import annotations

import numpy as np
import viser
import viser.uplot as uplot

__all__ = ["CURSOR_COLOUR", "MAX_POINTS", "TimePlot", "thinned"]

MAX_POINTS = 800  # samples a plot keeps (as pairs: least and largest per bucket)
CURSOR_COLOUR = "#1c7ed6"  # the cursor line: blue, against the series' orange
SERIES_COLOUR = "#d9480f"


def thinned(t: np.ndarray, values: np.ndarray, most: int = MAX_POINTS) -> tuple[np.ndarray, ...]:
    """(t, values) kept to at most `most` samples: per bucket of consecutive samples, the
    least and the largest value, in time order (NaN samples count as neither).

    Args:
        t: sample times, ascending, shape (n,) [s].
        values: the series, shape (n,).
        most: samples to keep at most (even).

    Returns:
        The kept times and values, each shape (≤ most,).
    """
    if len(t) <= most:
        return t, values
    keep: list[int] = []
    for bucket in np.array_split(np.arange(len(t)), most // 2):
        finite = bucket[np.isfinite(values[bucket])]
        if finite.size == 0:
            keep.append(int(bucket[0]))
            continue
        low, high = finite[np.argmin(values[finite])], finite[np.argmax(values[finite])]
        keep.extend(sorted({int(low), int(high)}))
    return t[keep], values[keep]


class TimePlot:
    """One series against time in the panel, with a cursor line at a time.

    Args:
        gui: the viser GUI to add the plot to.
        label: the series' name and unit, also the plot's title.
        t: sample times, ascending, shape (n,) [s].
        values: the series, shape (n,).
        log: a logarithmic value axis (the values must be positive).

    Attributes:
        t: the plotted times [s] (thinned).
        values: the plotted values (thinned).
        cursor: the cursor's time [s], or None before the first `at`.
        handle: viser's handle of the plot.
    """

    def __init__(
        self, gui: viser.GuiApi, label: str, t: np.ndarray, values: np.ndarray, log: bool = False
    ) -> None:
        self.t, self.values = thinned(np.asarray(t, float), np.asarray(values, float))
        self.cursor: float | None = None
        value_scale = uplot.Scale(distr=3, log=10) if log else uplot.Scale()
        self.handle = gui.add_uplot(
            data=self._data(None),
            series=(
                uplot.Series(label="t [s]"),
                uplot.Series(label=label, stroke=SERIES_COLOUR, scale="value"),
                uplot.Series(
                    label="now",
                    stroke=CURSOR_COLOUR,
                    width=2.0,
                    scale="cursor",
                    spanGaps=False,
                    points=uplot.Series_Points(show=False),
                ),
            ),
            scales={
                "x": uplot.Scale(time=False),
                "value": value_scale,
                "cursor": uplot.Scale(auto=False, range=(0.0, 1.0)),
            },
            # The cursor's scale has no axis; a log axis's minor ticks and grid (1-9 in every
            # decade) are drawn faint, or they blacken it.
            axes=(uplot.Axis(), _value_axis(log)),
            title=label,
            aspect=2.0,
        )

    def at(self, t: float) -> None:
        """Put the cursor at time t [s] (nothing is sent when it stays on the same sample).

        Args:
            t: the scene's time [s].
        """
        k = int(np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 1))
        if self.cursor is not None and self.t[k] == self.cursor:
            return
        self.cursor = float(self.t[k])
        self.handle.data = self._data(k)

    def remove(self) -> None:
        """Take the plot off the panel."""
        self.handle.remove()

    def _data(self, k: int | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, values, cursor) with sample k doubled, the cursor's 0 and 1 on its two copies
        (all NaN without a cursor)."""
        if k is None:
            return self.t, self.values, np.full(len(self.t), np.nan)
        t = np.insert(self.t, k, self.t[k])
        values = np.insert(self.values, k, self.values[k])
        cursor = np.full(len(t), np.nan)
        cursor[k], cursor[k + 1] = 0.0, 1.0
        return t, values, cursor


def _value_axis(log: bool) -> uplot.Axis:
    """The value axis: uPlot's, or for a log scale one with faint, hairline ticks and grid."""
    if not log:
        return uplot.Axis(scale="value")
    faint = {"stroke": "#e5e5e5", "width": 0.5}
    return uplot.Axis(scale="value", grid=uplot.Axis_Grid(**faint), ticks=uplot.Axis_Ticks(**faint))
