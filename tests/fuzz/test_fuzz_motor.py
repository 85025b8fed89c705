"""`articula motor analyze [--preset|--params FILE] [--voltage] [--torque] [--current]`."""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tests.fuzz import bases
from tests.fuzz.contract import Example
from tests.fuzz.fuzzing import FUZZ_SETTINGS, Fuzz
from tests.fuzz.inputs import write_input
from tests.fuzz.mutations import UNCHANGED, Mutation, mutations, set_

pytestmark = pytest.mark.fuzz

# What a valid motor always has: its matrices, poles and steady state (ω_c may be none).
FINITE = ["A", "B", "poles", "steady_state.omega", "steady_state.i"]
NUMBERS = (
    "0",
    "-1",
    "1e308",
    "-1e308",
    "1e-308",
    "5e-324",
    "1e309",
    "-1e309",
    "nan",
    "inf",
    "-inf",
    "1" + "0" * 30,
    "1" + "0" * 400,
    "abc",
    "",
    " ",
    "0x10",
    "1,5",
)
PRESETS = ("table4.1", "table4.2", "", "nope", "TABLE4.1", "table4.1\n", "x" * 1000)
OPTIONS = ("--voltage", "--torque", "--current")


@dataclass(frozen=True)
class MotorCase:
    """One change at a time: an option's value, the preset, or one field of a params file.

    source: "preset", "params", "both" (--preset and --params) or "neither".
    """

    source: str = "preset"
    preset: str = "table4.1"
    params: Mutation = UNCHANGED
    option: str = "--voltage"
    value: str | None = None
    as_json: bool = True


def motor_cases() -> st.SearchStrategy[MotorCase]:
    return st.one_of(
        st.builds(
            MotorCase,
            option=st.sampled_from(OPTIONS),
            value=st.sampled_from(NUMBERS),
            as_json=st.booleans(),
        ),
        st.builds(
            MotorCase,
            source=st.just("params"),
            params=mutations(bases.MOTOR_PARAMS),
            as_json=st.booleans(),
        ),
        st.builds(
            MotorCase,
            source=st.sampled_from(("preset", "both", "neither")),
            preset=st.sampled_from(PRESETS),
            as_json=st.booleans(),
        ),
    )


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=motor_cases())
@example(case=MotorCase(value="1e308"))
@example(case=MotorCase(option="--torque", value="1e308"))
@example(case=MotorCase(option="--current", value="-1e308"))
@example(case=MotorCase(source="params", params=set_(("R",), 1e308)))
@example(case=MotorCase(source="params", params=set_(("J",), 1e-308)))
@example(case=MotorCase(source="params", params=set_(("K",), 1e200), as_json=False))
@example(case=MotorCase(source="params", params=set_(("L",), 1e-308)))  # found by the fuzzer
@example(case=MotorCase(source="params", params=set_(("J",), 5e-324)))  # found by the fuzzer
def test_motor_analyze(fuzz: Fuzz, case: MotorCase):
    folder = fuzz.workdir()
    args = ["motor", "analyze"]
    inputs = {}
    if case.source in ("preset", "both"):
        args += ["--preset", case.preset]
    if case.source in ("params", "both"):
        inputs["motor.toml"] = write_input(folder / "motor.toml", bases.MOTOR_PARAMS, case.params)
        args += ["--params", "motor.toml"]
    if case.value is not None:
        args += [case.option, case.value]
    args += ["--json"] if case.as_json else []
    change = (
        f"{case.option} {case.value!r}"
        if case.value is not None
        else f"params file: {case.params!r}"
        if case.source == "params"
        else f"{case.source}, --preset {case.preset!r}"
    )
    fuzz.check(Example("motor analyze", args, folder, None, case.as_json, FINITE, inputs, change))
