"""rigs/programs.py: reference programs against chapter 2's reference, and their encoding."""

from __future__ import annotations

import numpy as np
import pytest

from articula.book.ch2.tuning import step_reference
from articula.errors import ConfigError, DeviceError
from articula.experiments.pneunet import AngleReference, reference_deg
from articula.rigs.programs import Program, Shape, steps

PERIOD = 1.0 / 30.0


def test_steps_are_chapter_2s_steps_sample_for_sample():
    levels, hold = (15.0, 45.0, 75.0), 4.0
    t = np.arange(round(len(levels) * hold / PERIOD)) * PERIOD
    assert np.array_equal(steps(levels, hold).at(t), step_reference(levels, hold, PERIOD))


def test_a_sinusoid_is_chapter_2s_sinusoid():
    t = np.arange(900) * PERIOD
    book = reference_deg(AngleReference(offset_deg=40, amplitude_deg=30, frequency=0.2), t)
    assert np.allclose(Program(Shape.SINUSOID, (40.0, 30.0, 0.2)).at(t), book, atol=1e-12)


def test_programs_round_trip_through_float32():
    program = steps((30.0, 60.0), 2.0)
    assert Program.decode(program.encode()) == program
    assert Program(Shape.CONSTANT, (12.5,)).at(np.array([0.0, 9.0])).tolist() == [12.5, 12.5]


@pytest.mark.parametrize(
    ("shape", "values", "words"),
    [
        (Shape.CONSTANT, (), "takes 1"),
        (Shape.SINUSOID, (1.0, 2.0), "takes 3"),
        (Shape.STEPS, (0.0, 10.0), "hold time must be > 0"),
        (Shape.STEPS, (1.0,), "hold time and"),
        (Shape.CONSTANT, (float("nan"),), "finite"),
    ],
)
def test_bad_programs_are_refused(shape, values, words):
    with pytest.raises(ConfigError, match=words):
        Program(shape, values)


def test_a_damaged_program_body_does_not_decode():
    body = steps((30.0,), 1.0).encode()
    for damaged in (body[:1], body[:-1], b"\x07" + body[1:]):
        with pytest.raises(DeviceError, match="SET_REFERENCE"):
            Program.decode(damaged)
