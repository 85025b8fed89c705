"""`articula run CONFIG --out DIR [--json]`: one field of each experiment's config mutated."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tests.fuzz import bases
from tests.fuzz.contract import Example
from tests.fuzz.fuzzing import FUZZ_SETTINGS, Fuzz
from tests.fuzz.inputs import OUT_VARIANTS, prepare_out, write_input
from tests.fuzz.mutations import UNCHANGED, Mutation, add, mutations, set_

pytestmark = pytest.mark.fuzz

# Metrics every valid config of the experiment defines (others are null by design, e.g. a
# rise time of a sinusoidal reference).
FINITE = {
    "motor.current": [
        "steady_state_error",
        "current_rms_error",
        "noise_rms",
        "speed_mean",
        "saturation_fraction",
    ],
    "pneunet.pid": [
        "error_median_deg",
        "error_q1_deg",
        "error_q3_deg",
        "error_true_median_deg",
        "cost_median",
        "saturation_fraction",
    ],
    "softarm.damping": [
        "peak_deg",
        "deactuation_angle_deg",
        "peak_true_deg",
        "opposite_peak_pressure",
    ],
    "baornn.plan": ["rms_error", "max_error", "time_per_iteration_us"],
}


@dataclass(frozen=True)
class RunCase:
    """One change at a time: a mutation of the base config, or an odd --out; and --json."""

    mutation: Mutation
    as_json: bool = True
    out: str = "out"


def cases(base: dict[str, Any]) -> st.SearchStrategy[RunCase]:
    config = st.builds(RunCase, mutations(base), st.booleans())
    out = st.builds(RunCase, st.just(UNCHANGED), st.booleans(), st.sampled_from(OUT_VARIANTS))
    return st.one_of(config, config, config, out)  # an odd --out in a quarter of the examples


def check_run(fuzz: Fuzz, base: dict[str, Any], case: RunCase) -> None:
    folder = fuzz.workdir()
    text = write_input(folder / "config.toml", base, case.mutation)
    out = prepare_out(folder, case.out)
    name = base["experiment"]
    args = ["run", "config.toml", "--out", case.out] + (["--json"] if case.as_json else [])
    finite = [f"metrics.{m}" for m in FINITE[name]]
    change = repr(case.mutation) if case.out == "out" else f"--out {case.out!r}"
    fuzz.check(
        Example(f"run {name}", args, folder, out, case.as_json, finite, {"config.toml": text},
                change)
    )  # fmt: skip


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=cases(bases.MOTOR_CURRENT))
@example(case=RunCase(set_(("reference", "current"), -1e308)))
@example(case=RunCase(set_(("duration",), 1e9)))
@example(case=RunCase(set_(("controller", "filter_order"), 2**63, "2**63")))
def test_run_motor_current(fuzz: Fuzz, case: RunCase):
    check_run(fuzz, bases.MOTOR_CURRENT, case)


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=cases(bases.PNEUNET_PID))
@example(case=RunCase(set_(("duration",), 1e9)))
@example(case=RunCase(set_(("plant", "pwm_period"), 1e-308)))
def test_run_pneunet_pid(fuzz: Fuzz, case: RunCase):
    check_run(fuzz, bases.PNEUNET_PID, case)


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=cases(bases.SOFTARM_DAMPING))
@example(case=RunCase(set_(("dt",), 1e-12)))
@example(case=RunCase(set_(("hold",), 1e308)))
@example(case=RunCase(set_(("sensor", "rate"), 1.0)))  # found by the fuzzer (from 1e-308)
def test_run_softarm_damping(fuzz: Fuzz, case: RunCase):
    check_run(fuzz, bases.SOFTARM_DAMPING, case)


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=cases(bases.PLANS["baornn-circle"]))
@example(case=RunCase(set_(("planner", "duration"), 1e9)))
@example(case=RunCase(set_(("obstacles", 0, "scale"), 1e308)))
@example(case=RunCase(add(("robot",), "ee_frame", "nope")))
@example(case=RunCase(UNCHANGED, out="."))
@example(case=RunCase(UNCHANGED, out="mine"))
def test_run_baornn_plan(fuzz: Fuzz, case: RunCase):
    check_run(fuzz, bases.PLANS["baornn-circle"], case)
