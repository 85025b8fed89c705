"""Numbers as the report prints them: a dash for a missing or non-finite value."""

from __future__ import annotations

import math


def fixed(x: float | None, digits: int) -> str:
    """x with `digits` decimals, or "—"."""
    return "—" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def milli(x: float | None) -> str:
    """x [s, A, m] in milli-units with one decimal, or "—"."""
    return "—" if x is None or not math.isfinite(x) else f"{1e3 * x:.1f}"


def degrees(x: float | None) -> str:
    """x [rad] in degrees with one decimal, or "—"."""
    return "—" if x is None or not math.isfinite(x) else f"{math.degrees(x):.1f}"


def significant(x: float | None) -> str:
    """x to three significant digits; "> max tested" for inf; "—" for None or NaN."""
    if x is None or math.isnan(x):
        return "—"
    return "> max tested" if math.isinf(x) else f"{x:.3g}"


def finite_or_none(x: float | None) -> float | None:
    """x as a float, or None where JSON cannot hold it."""
    return None if x is None or not math.isfinite(x) else float(x)
