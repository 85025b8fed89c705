"""The PneuNet rig's firmware (firmware/src/pneunet.c) in simavr on the simulated actuator:
one experiment agrees with the Python rig's sample for sample until the first one-count
difference of the flex sensor's ADC (float32 on the AVR, the valve's duty in Timer1's 8333
ticks rather than 255 steps), and chapter 2's coordinate descent runs on it to a tuning as
good as the in-process one."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from articula.book.ch2.tuning import (
    AutoConfig,
    TuningConfig,
    auto_run,
    auto_seed,
    step_reference,
)
from articula.control.pid import GainSchedule
from articula.errors import ConfigError
from articula.loops.pneunet_pid import SimulatedRig
from articula.plants.pneunet import PneuNetParams
from articula.rigs.emulator import Emulator
from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetDevice, PneuNetPins, PneuNetRig, encode_gains
from articula.rigs.programs import Program, Shape, steps
from articula.rigs.protocol import Kind
from articula.rigs.run import run_program
from articula.tuning.response import tuning_cost

pytestmark = pytest.mark.firmware
LSB = 0.1758  # [°] one code of the 10-bit ADC on the flex sensor's 2.5 V over 90°
PROGRAM = steps((30.0, 60.0), 2.0)


def run(link: Link, schedule: GainSchedule, program: Program, seed: int) -> np.ndarray:
    """One run of `program` under `schedule`: (reference, angle, pwm) per period."""
    link.command(Kind.SET_GAINS, encode_gains(schedule))
    link.command(Kind.SET_REFERENCE, program.encode())
    return run_program(link, 4.0, seed)[1]


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    "schedule",
    [
        GainSchedule("constant", [[2.0, 1.5, 0.05]]),
        GainSchedule("piecewise", [[1.0, 2.0, 0.02], [2.0, 3.0, 0.04]], [20.0, 50.0]),
        GainSchedule("fuzzy", [[1.0, 2.0, 0.02], [2.0, 3.0, 0.04], [0.5, 4.0, 0.0]],
                     [20.0, 45.0, 70.0]),
    ],
    ids=lambda s: s.kind,
)  # fmt: skip
def test_an_experiment_on_the_firmware_is_the_python_rigs_to_a_count(schedule, on_plant):
    program = Program(Shape.SINUSOID, (45.0, 20.0, 0.5)) if schedule.kind == "fuzzy" else PROGRAM
    rig = on_plant("pneunet", PneuNetPins())
    with Link(rig.path) as link, Emulator(PneuNetDevice()) as emulator, \
            Link(emulator.path) as python:  # fmt: skip
        there, here = run(link, schedule, program, 7), run(python, schedule, program, 7)
    assert there.shape == here.shape == (120, 3)
    assert np.allclose(there[:, 0], here[:, 0], atol=1e-4)  # the reference program
    apart = np.abs(there[:, 1] - here[:, 1])
    first = int(np.argmax(apart > 1e-3)) if (apart > 1e-3).any() else len(apart)
    assert first >= 40  # identical, float32 aside, for over a second
    assert apart.max() <= 2 * LSB + 1e-3  # then a count or two apart
    t = np.arange(len(here)) / 30
    m_there, m_here = (tuning_cost(t, r[:, 0], r[:, 1]) for r in (there, here))
    assert m_there == pytest.approx(m_here, rel=0.02)


@pytest.mark.slow
def test_coordinate_descent_on_the_firmware_tunes_as_well_as_in_process(on_plant):
    config = TuningConfig(auto=AutoConfig(hold=2.0, max_iterations=6))
    levels = (30.0, 60.0)
    here = auto_run(config, levels, 0).result
    rig = on_plant("pneunet", PneuNetPins(config.plant))
    with Link(rig.path) as link:
        a = config.auto
        pneunet = PneuNetRig(link, steps(levels, a.hold), len(levels) * a.hold,
                             auto_seed(config, 0))  # fmt: skip
        there = auto_run(config, levels, 0, rig=pneunet).result
        assert link.stats.dropped == link.stats.crc_errors == 0
    # The descent compares costs; one ADC count apart in one experiment can turn a step,
    # so the path differs: measured here, 30 experiments to M = 34.6 (K = 0.593, 2.95,
    # 0.0054) against 33 to M = 34.3 (K = 0.593, 4.05, 0.027): M is flat in K_i and K_d.
    assert pneunet.calls == there.evaluations
    assert abs(there.evaluations - here.evaluations) <= 0.25 * here.evaluations
    assert there.cost == pytest.approx(here.cost, rel=0.05)
    # The firmware's tuning, tried on the simulated actuator, is as good as the in-process one.
    simulated = SimulatedRig(config.plant, step_reference(levels, a.hold, config.plant.pwm_period),
                             auto_seed(config, 0))  # fmt: skip
    m_there, m_here = (float(tuning_cost(r.t, r.reference, r.measured))
                       for r in (simulated(there.k), simulated(here.k)))  # fmt: skip
    assert m_there <= 1.05 * m_here


def test_open_loop_output_holds_its_count_until_stop(on_plant):
    rig = on_plant("pneunet", PneuNetPins())
    with Link(rig.path) as link:
        link.command(Kind.SET_OUTPUT, struct.pack("<Bf", 0, 128.6))
        held = run_program(link, 1.0, 0)[1]
        link.command(Kind.STOP)
        closed = run_program(link, 1.0, 0)[1]
    assert np.all(held[:, 2] == 128)  # floor of the count, every period
    assert np.all(held[-10:, 1] > held[0, 1] + 5)  # the finger bends
    assert not np.all(closed[:, 2] == 128)  # STOP ended the open loop


def test_a_plant_the_firmware_is_not_built_for_is_refused_by_field():
    with pytest.raises(ConfigError, match=r"plant.pwm_period.*firmware/src/pneunet.c"):
        PneuNetPins(PneuNetParams(pwm_period=0.02))
