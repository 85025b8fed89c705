"""`articula sweep SPEC --out DIR [--workers N] [--json]`: one field of the spec mutated, huge
grids, empty runs, odd worker counts."""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tests.fuzz import bases
from tests.fuzz.contract import Example
from tests.fuzz.fuzzing import FUZZ_SETTINGS, Fuzz
from tests.fuzz.inputs import OUT_VARIANTS, prepare_out, write_input
from tests.fuzz.mutations import UNCHANGED, Mutation, mutations, set_

pytestmark = pytest.mark.fuzz

# Ten keys of the base with ten valid values each.
_KEYS = (
    "seed",
    "controller.kp",
    "controller.ki",
    "speed_controller.kp",
    "speed_controller.ki",
    "reference.current",
    "reference.speed",
    "sensor.noise_pp",
    "sensor.zero_voltage",
    "pwm.v_max",
)


def _values(key: str) -> list[float | int]:
    if key == "seed":
        return list(range(10))
    table, leaf = key.split(".")
    value = bases.MOTOR_CURRENT[table][leaf]
    return [value * (1 + k / 100) for k in range(10)]


def grid(keys: int) -> dict[str, list[float | int]]:
    """A grid of 10**keys points."""
    return {key: _values(key) for key in _KEYS[:keys]}


SPECIAL = (
    set_(("grid",), grid(10), "10 keys × 10 values (10**10 points)"),
    set_(("grid",), grid(6), "6 keys × 10 values (10**6 points)"),
    set_(("grid",), {"seed": list(range(10**5))}, "{seed = range(10**5)}"),
    set_(("runs",), []),
    set_(("runs",), [{}] * 1000, "[{}] * 1000 (the same config 1000 times)"),
    set_(("grid",), {"seed": []}, "{seed = []}"),
    set_(("grid",), {"nope.deeper": [1, 2]}, "{'nope.deeper' = [1, 2]}"),
    set_(("grid",), {"seed.x": [1, 2]}, "{'seed.x' = [1, 2]} (seed is not a table)"),
)
WORKERS = ("1", "2", "0", "-1", "abc", "", str(10**6), str(2**63), "1e3")


@dataclass(frozen=True)
class SweepCase:
    """One change at a time: the spec (a field, or a special grid or runs), --workers or
    --out; and --json."""

    mutation: Mutation
    workers: str = "1"
    as_json: bool = True
    out: str = "out"


def sweep_cases() -> st.SearchStrategy[SweepCase]:
    spec = st.builds(SweepCase, mutations(bases.SWEEP), as_json=st.booleans())
    return st.one_of(
        spec,
        spec,
        st.builds(SweepCase, st.sampled_from(SPECIAL), as_json=st.booleans()),
        st.builds(SweepCase, st.just(UNCHANGED), st.sampled_from(WORKERS), st.booleans()),
        st.builds(SweepCase, st.just(UNCHANGED), as_json=st.booleans(),
                  out=st.sampled_from(OUT_VARIANTS)),
    )  # fmt: skip


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=sweep_cases())
@example(case=SweepCase(set_(("runs",), [])))
@example(case=SweepCase(SPECIAL[1]))
@example(case=SweepCase(SPECIAL[0]))
@example(case=SweepCase(set_(("base", "duration"), 1e9)))
@example(case=SweepCase(UNCHANGED, workers=str(10**6)))
@example(case=SweepCase(UNCHANGED, workers=str(2**63)))  # found by the fuzzer
def test_sweep(fuzz: Fuzz, case: SweepCase):
    folder = fuzz.workdir()
    text = write_input(folder / "sweep.toml", bases.SWEEP, case.mutation)
    out = prepare_out(folder, case.out)
    args = ["sweep", "sweep.toml", "--out", case.out, "--workers", case.workers]
    args += ["--json"] if case.as_json else []
    change = (
        f"--workers {case.workers!r}"
        if case.workers != "1"
        else f"--out {case.out!r}"
        if case.out != "out"
        else repr(case.mutation)
    )
    fuzz.check(Example("sweep", args, folder, out, case.as_json, positive=["runs"],
                       inputs={"sweep.toml": text}, mutation=change))  # fmt: skip
