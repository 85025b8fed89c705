"""Chamber pressures that bend the six-chamber actuator away from any side (Sect. 3.2.2)."""

from __future__ import annotations

import math

import numpy as np

from articula.plants.six_chamber import CHAMBERS


def side_pressures(side_deg: float, gauge: float) -> np.ndarray:
    """Gauge pressures [Pa] of the six chambers that push as one chamber of `gauge` at `side_deg`.

    The body bends toward side_deg + 180°. Between two chambers the force vector gauge·ê_side
    is split over the two nearest chambers (p_a ê_a + p_b ê_b = gauge·ê_side, both ≥ 0,
    neither above gauge).

    Args:
        side_deg: side that is pressurised, chamber i sitting at 60°·i [deg].
        gauge: gauge pressure of the equivalent single chamber [Pa].

    Returns:
        The gauge pressure of each chamber, shape (6,) [Pa].
    """
    side = float(side_deg) % 360.0
    lower = int(side // 60.0) % CHAMBERS  # % again: a tiny negative side_deg % 360.0 is 360.0
    alpha = math.radians(side - 60.0 * (side // 60.0))
    sixty = math.radians(60.0)
    pressures = np.zeros(CHAMBERS)
    pressures[lower] += gauge * math.sin(sixty - alpha) / math.sin(sixty)
    pressures[(lower + 1) % CHAMBERS] += gauge * math.sin(alpha) / math.sin(sixty)
    return pressures


def bend_direction(side_deg: float) -> np.ndarray:
    """Unit vector toward which the top tilts when `side_deg` is pressurised.

    Args:
        side_deg: side that is pressurised, chamber i sitting at 60°·i [deg].

    Returns:
        The horizontal bend direction, side_deg + 180°, shape (2,).
    """
    away = math.radians(side_deg + 180.0)
    return np.array([math.cos(away), math.sin(away)])
