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
    """A simulated run: the plant samples, the sensor's samples and the bending direction.

    Attributes:
        sim: the plant's recorded samples.
        sensor_t: the orientation sensor's sample times, shape (n,) [s].
        sensor_bend: bending vector from the sensor's roll/pitch/yaw, shape (n, 2) [rad].
        direction: unit vector toward which the side bends the body, shape (2,).
        t_off: deactuation instant, when the side is vented [s].
    """

    sim: Simulation
    sensor_t: np.ndarray
    sensor_bend: np.ndarray
    direction: np.ndarray
    t_off: float


def valve_program(
    p: SixChamberParams, side_deg: float, gauge: float, hold: float, damping: DampingPolicy
) -> ValveSchedule:
    """Valve events: fill side `side_deg` to `gauge` [Pa], hold it, vent at `hold` [s], pulse.

    A chamber at the supply pressure stays open to the pump; one below it is regulated to its
    pressure (REGULATE), so at the vent command every chamber of the side is at the pressure
    it was commanded, the denominator of Eq. (3.4).

    Args:
        p: actuator constants.
        side_deg: side that is pressurised, chamber i sitting at 60°·i [deg].
        gauge: gauge pressure of the equivalent single chamber at `side_deg` [Pa].
        hold: time at which the side is vented [s].
        damping: the policy whose pulse on the opposite chambers damps the deactuation.

    Returns:
        The valve events of the whole run.
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
    p: SixChamberParams,
    sensor: OrientationSensorParams,
    program: ValveSchedule,
    side_deg: float,
    hold: float,
    after: float,
    dt: float,
    record_every: int,
    rng: np.random.Generator,
) -> Deactuation:
    """Run `program` for hold + after [s] at step dt [s], keeping every record_every-th
    sample, and read the sensor (its noise from `rng`).

    Args:
        p: actuator constants.
        sensor: the orientation sensor's rate and noise.
        program: the valve events (valve_program).
        side_deg: side that was pressurised [deg], for the bending direction.
        hold: deactuation instant [s], as in the program.
        after: time simulated after the deactuation [s].
        dt: RK4 step [s].
        record_every: keep every record_every-th step.
        rng: random generator of the sensor noise.

    Returns:
        The plant's and the sensor's samples of the run.
    """
    sim = integrate(p, program, hold + after, dt, record_every)
    ts, euler = read(sensor, sim.t, sim.beta, rng)
    return Deactuation(sim, ts, bend_from_euler(euler), bend_direction(side_deg), hold)
