"""`articula plan SCENE --out DIR` and `articula scene check SCENE [--q] [--metric]`."""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tests.fuzz import bases
from tests.fuzz.contract import Example
from tests.fuzz.fuzzing import FUZZ_SETTINGS, Fuzz
from tests.fuzz.inputs import OUT_VARIANTS, prepare_out, write_input
from tests.fuzz.mutations import HUGE, UNCHANGED, Mutation, Value, add, mutations, set_

pytestmark = pytest.mark.fuzz

PLAN_FINITE = ["metrics.rms_error", "metrics.max_error", "metrics.time_per_iteration_us"]
SCENE_FINITE = ["q", "ee_position"]


@dataclass(frozen=True)
class PlanCase:
    """One change at a time to one of the base plans (bases.PLANS): a mutation of the file,
    or an odd --out; and --json."""

    base: str
    mutation: Mutation
    as_json: bool = True
    out: str = "out"


def plan_cases() -> st.SearchStrategy[PlanCase]:
    base = st.sampled_from(sorted(bases.PLANS))
    scene = base.flatmap(
        lambda name: st.builds(PlanCase, st.just(name), mutations(bases.PLANS[name]),
                               st.booleans())
    )  # fmt: skip
    out = st.builds(PlanCase, base, st.just(UNCHANGED), st.booleans(),
                    st.sampled_from(OUT_VARIANTS))  # fmt: skip
    return st.one_of(scene, scene, scene, out)  # an odd --out in a quarter of the examples


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=plan_cases())
@example(case=PlanCase("baornn-circle", set_(("obstacles", 0, "scale"), 1e308)))
@example(case=PlanCase("baornn-circle", set_(("obstacles", 0, "scale"), [1.0, 1e200, 1.0])))
@example(case=PlanCase("baornn-circle", set_(("planner", "duration"), 1e9)))
@example(case=PlanCase("baornn-circle", set_(("planner", "duration"), 1e5)))
@example(case=PlanCase("baornn-circle", set_(("planner", "dt"), 1e-12)))
@example(case=PlanCase("baornn-circle", add(("robot",), "ee_frame", "nope")))
@example(case=PlanCase("baornn-circle", set_(("obstacles", 0, "mesh"), "garbage.stl")))
@example(case=PlanCase("baornn-no-obstacles", UNCHANGED, as_json=False))
@example(case=PlanCase("baornn-no-obstacles", UNCHANGED, as_json=True))
@example(case=PlanCase("baornn-circle", UNCHANGED, out="mine"))
def test_plan(fuzz: Fuzz, case: PlanCase):
    folder = fuzz.workdir()
    text = write_input(folder / "scene.toml", bases.PLANS[case.base], case.mutation)
    out = prepare_out(folder, case.out)
    args = ["plan", "scene.toml", "--out", case.out] + (["--json"] if case.as_json else [])
    change = repr(case.mutation) if case.out == "out" else f"--out {case.out!r}"
    fuzz.check(Example("plan", args, folder, out, case.as_json, PLAN_FINITE,
                       {"scene.toml": text}, f"{case.base}: {change}"))  # fmt: skip


def _q(label: str, text: str) -> Value:
    return Value(label, text)


# --q values: non-finite, huge, too short or long, not numbers.
Q_VALUES = (
    _q("0 × 7", bases.Q0),
    _q("1e308 × 7", ",".join(["1e308"] * 7)),
    _q("-1e308 × 7", ",".join(["-1e308"] * 7)),
    _q("1e309 × 7 (inf)", ",".join(["1e309"] * 7)),
    _q("nan × 7", ",".join(["nan"] * 7)),
    _q("inf, 0 × 6", ",".join(["inf"] + ["0"] * 6)),
    _q("5e-324 × 7", ",".join(["5e-324"] * 7)),
    _q("3.5 × 7 (outside the limits)", ",".join(["3.5"] * 7)),
    _q("0, 0", "0,0"),
    _q("0 × 8", ",".join(["0"] * 8)),
    _q("0 × 10**5", ",".join(["0"] * HUGE)),
    _q("'1' + '0' * 400 × 7", ",".join(["1" + "0" * 400] * 7)),
    _q("''", ""),
    _q("','", ","),
    _q("' '", " "),
    _q("'\\n'", "\n"),
    _q("'nope'", "nope"),
    _q("0 × 6, 'x'", ",".join(["0"] * 6 + ["x"])),
    _q("0;0;…", ";".join(["0"] * 7)),
    _q("-1, 0 × 6", ",".join(["-1"] + ["0"] * 6)),
)
METRICS = ("gjk", "vertex", "", "nope", "GJK", "vertex ", "\n", "x" * 1000)


@dataclass(frozen=True)
class SceneCase:
    """One change at a time: the scene file, --q, or --metric."""

    base: str
    mutation: Mutation
    q: Value | None = None
    metric: str | None = None
    as_json: bool = True


def scene_cases() -> st.SearchStrategy[SceneCase]:
    base = st.sampled_from(sorted(bases.SCENES))
    scene = base.flatmap(
        lambda name: st.builds(
            SceneCase, st.just(name), mutations(bases.SCENES[name]), as_json=st.booleans()
        )
    )
    q = st.builds(
        SceneCase, base, st.just(UNCHANGED), q=st.sampled_from(Q_VALUES), as_json=st.booleans()
    )
    metric = st.builds(
        SceneCase,
        base,
        st.just(UNCHANGED),
        metric=st.sampled_from(METRICS),
        as_json=st.booleans(),
    )
    return st.one_of(scene, q, metric)


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=scene_cases())
@example(case=SceneCase("builtin", set_(("obstacles", 0, "scale"), 1e308)))
@example(case=SceneCase("builtin", set_(("obstacles", 0, "scale"), 1e200)))
@example(case=SceneCase("builtin", UNCHANGED, q=Q_VALUES[1]))
@example(case=SceneCase("builtin", UNCHANGED, q=Q_VALUES[4]))
@example(case=SceneCase("builtin", add(("robot",), "ee_frame", "nope")))
@example(case=SceneCase("urdf", set_(("robot", "ee_frame"), "nope")))
@example(case=SceneCase("builtin", set_(("obstacles", 0, "mesh"), "garbage.stl")))
def test_scene_check(fuzz: Fuzz, case: SceneCase):
    folder = fuzz.workdir()
    text = write_input(folder / "scene.toml", bases.SCENES[case.base], case.mutation)
    args = ["scene", "check", "scene.toml"]
    if case.q is not None:
        args += ["--q", case.q.data]
    if case.metric is not None:
        args += ["--metric", case.metric]
    args += ["--json"] if case.as_json else []
    change = (
        f"--q {case.q!r}"
        if case.q is not None
        else f"--metric {case.metric!r}"
        if case.metric is not None
        else repr(case.mutation)
    )
    fuzz.check(
        Example(
            "scene check",
            args,
            folder,
            None,
            case.as_json,
            SCENE_FINITE,
            {"scene.toml": text},
            f"{case.base}: {change}",
        )
    )
