"""Active oscillation damping of chapter 3: pulse the chambers opposite the ones deactuated."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import Field

from articula.plants.six_chamber import CHAMBERS, SixChamberParams
from articula.plants.six_chamber_sim import FILL, HOLD, VENT, fill_time
from articula.validation import NonNegative, StrictModel


class DampingPolicy(StrictModel):
    """On deactuating a side, pulse the opposite side to δ times its pressure (Eq. 3.4).

    Attributes:
        delta: damping actuation ratio δ, at most 0.95 (0 = no damping).
        start: delay of the opposite fill after the deactuation command (0 = simultaneous,
            as in Sect. 3.2.4) [s].
        length: time from opening the fill valve to venting; the valve fills for the open
            time that reaches δ·P, holds for the rest, and vents no earlier than filled
            (0 = vent as soon as filled, the brief pulse) [s].
    """

    delta: Annotated[float, Field(ge=0, le=0.95, allow_inf_nan=False)] = 0.0
    start: NonNegative = 0.0
    length: NonNegative = 0.0

    def events(
        self, p: SixChamberParams, pressures: np.ndarray, t_off: float
    ) -> list[tuple[float, int, int]]:
        """Valve events (time [s], chamber, mode) of the pulse for a deactuation at t_off [s].

        Chamber i's pulse goes to chamber i + 3 at δ·pressures[i], filled by the valve open
        time that reaches it.

        Args:
            p: parameters of the six-chamber actuator (supply and valve flow).
            pressures: gauge pressures of the deactuated chambers, shape (6,) [Pa].
            t_off: time of the deactuation command [s].

        Returns:
            The valve events as (time [s], chamber index, valve mode FILL/HOLD/VENT) tuples,
            empty if δ = 0.
        """
        events: list[tuple[float, int, int]] = []
        if self.delta == 0:
            return events
        for i in range(CHAMBERS):
            if pressures[i] <= 0:
                continue
            opposite = (i + CHAMBERS // 2) % CHAMBERS
            t_fill = t_off + self.start
            # δ of Eq. (3.4) via open time; finite, since δ ≤ 0.95 keeps δ·P below supply.
            t_open = fill_time(p, self.delta * pressures[i])
            events.append((t_fill, opposite, FILL))
            events.append((t_fill + t_open, opposite, HOLD))
            events.append((t_fill + max(self.length, t_open), opposite, VENT))  # after HOLD
        return events
