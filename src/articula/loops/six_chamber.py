"""The six-chamber actuator's deactuation run: fill a side, hold, vent, pulse; read the sensor.

The valve program (Sect. 3.4) drives `plants.six_chamber_sim`; the damping policy adds the
opposite chambers' pulse (`control.damping`); the orientation sensor samples the top.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from articula.control.chamber_allocation import bend_direction, side_pressures
from articula.control.damping import DampingPolicy
from articula.plants.orientation_sensor import OrientationSensorParams, bend_from_euler, read
from articula.plants.six_chamber import CHAMBERS, SixChamberParams
from articula.plants.six_chamber_sim import (
    FILL,
    REGULATE,
    VENT,
    Simulation,
    ValveSchedule,
    integrate,
)


@dataclass(frozen=True)
class Deactuation:
    """A simulated run: the plant samples, the sensor's samples and the bending direction."""

    sim: Simulation
    sensor_t: np.ndarray
    sensor_bend: np.ndarray  # (n, 2) [rad], bending vector from the sensor's roll/pitch/yaw
    direction: np.ndarray  # unit vector toward which the side bends the body
    t_off: float  # deactuation instant [s]


def valve_program(
    p: SixChamberParams, side_deg: float, gauge: float, hold: float, damping: DampingPolicy
) -> ValveSchedule:
    """Valve events: fill side `side_deg` to `gauge` [Pa], hold it, vent at `hold` [s], pulse.

    A chamber at the supply pressure stays open to the pump; one below it is regulated to its
    pressure (REGULATE), so at the vent command every chamber of the side is at the pressure
    it was commanded, the denominator of Eq. (3.4).
    """
    pressures = side_pressures(side_deg, gauge)
    events: list = []
    for i in range(CHAMBERS):
        if pressures[i] <= 0:
            continue
        if pressures[i] >= p.supply * (1 - 1e-9):
            events.append((0.0, i, FILL))
        else:
            events.append((0.0, i, REGULATE, float(pressures[i])))
        events.append((hold, i, VENT))
    return ValveSchedule.build(events + damping.events(p, pressures, hold))


def deactuate(
    p: SixChamberParams, sensor: OrientationSensorParams, program: ValveSchedule,
    side_deg: float, hold: float, after: float, dt: float, record_every: int,
    rng: np.random.Generator,
) -> Deactuation:  # fmt: skip
    """Run `program` for hold + after [s] at step dt [s], keeping every record_every-th
    sample, and read the sensor (its noise from `rng`)."""
    sim = integrate(p, program, hold + after, dt, record_every)
    ts, euler = read(sensor, sim.t, sim.beta, rng)
    return Deactuation(sim, ts, bend_from_euler(euler), bend_direction(side_deg), hold)
