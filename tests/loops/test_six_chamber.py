"""loops/six_chamber.py: the deactuation run's valve program (fill or regulate a side, vent it at
`hold`, the damping pulse opposite) and the run itself, whose response turns with the command."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.control.chamber_allocation import bend_direction, side_pressures
from articula.control.damping import DampingPolicy
from articula.loops.six_chamber import deactuate, valve_program
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import SixChamberParams
from articula.plants.six_chamber_sim import FILL, REGULATE, VENT, ValveSchedule

P = SixChamberParams()
IDEAL = OrientationSensorParams(ideal=True)
HOLD_S = 1.5  # [s] the side is vented at this time
PULSE = DampingPolicy(delta=0.3, start=0.12, length=0.05)


def rotation(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s], [s, c]])


def _events(program: ValveSchedule) -> list[tuple]:
    return [(float(t), int(c), int(m)) for t, c, m in
            zip(program.times, program.chambers, program.modes, strict=True)]  # fmt: skip


def test_a_side_at_the_supply_pressure_is_filled_then_vented_at_hold():
    program = valve_program(P, 0.0, P.supply, HOLD_S, DampingPolicy())
    assert _events(program) == [(0.0, 0, FILL), (HOLD_S, 0, VENT)]


def test_a_side_between_two_chambers_is_regulated_to_their_share():
    # Side 30° is shared by chambers 0 and 1: p (1, 0) + p (1/2, √3/2) points at 30° for p = 1/√3.
    program = valve_program(P, 30.0, P.supply, HOLD_S, DampingPolicy())
    assert _events(program) == [
        (0.0, 0, REGULATE), (0.0, 1, REGULATE), (HOLD_S, 0, VENT), (HOLD_S, 1, VENT),
    ]  # fmt: skip
    np.testing.assert_allclose(program.targets[:2], P.supply / math.sqrt(3), rtol=1e-12)


def test_the_damping_pulse_follows_the_side_program():
    program = valve_program(P, 0.0, P.supply, HOLD_S, PULSE)
    pulse = PULSE.events(P, side_pressures(0.0, P.supply), HOLD_S)
    assert pulse and all(chamber == 3 for _, chamber, _ in pulse)  # opposite chamber 0
    assert _events(program) == [(0.0, 0, FILL), (HOLD_S, 0, VENT), *pulse]


def _run(side: float):
    """A run of side `side` [°] at the supply pressure with the pulse, 0.6 s after venting."""
    program = valve_program(P, side, P.supply, HOLD_S, PULSE)
    return deactuate(P, IDEAL, program, side, HOLD_S, 0.6, 1e-4, 10, np.random.default_rng(0))


def test_a_run_records_the_plant_and_the_sensor_until_after_the_vent():
    run = _run(0.0)
    assert run.t_off == HOLD_S
    np.testing.assert_allclose(run.direction, bend_direction(0.0))
    np.testing.assert_allclose(np.diff(run.sim.t), 1e-3)  # every 10th step of 0.1 ms
    assert run.sim.t[-1] == pytest.approx(HOLD_S + 0.6, abs=1e-3)
    # The ideal sensor samples every plant sample and reads the bend exactly.
    np.testing.assert_array_equal(run.sensor_t, run.sim.t)
    np.testing.assert_allclose(run.sensor_bend, run.sim.beta, atol=1e-12)


@pytest.mark.parametrize("side", [0.0, 30.0, 75.0])
def test_rotating_the_command_by_60_degrees_rotates_the_response(side):
    runs = [_run(s) for s in (side, side + 60.0)]
    rotated = runs[0].sim.beta @ rotation(60.0).T
    np.testing.assert_allclose(runs[1].sim.beta, rotated, atol=1e-9)
    np.testing.assert_allclose(runs[1].sim.gauge, np.roll(runs[0].sim.gauge, 1, axis=1), atol=1e-6)
    assert np.abs(runs[0].sim.beta).max() > math.radians(10)
