"""`articula reproduce CHAPTER --out DIR` with bad arguments only: never a real reproduction.

Either the chapter is not one (and the other options vary), or the chapter is one and exactly
one option is invalid in a way that must be caught before any work.
"""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tests.fuzz.contract import Example
from tests.fuzz.fuzzing import FUZZ_SETTINGS, Fuzz
from tests.fuzz.inputs import OUT_VARIANTS, prepare_out

pytestmark = pytest.mark.fuzz

VALID_CHAPTERS = ("all", "ch1", "ch2", "ch3", "ch4")
BAD_CHAPTERS = (
    "",
    " ",
    "\n",
    "nope",
    "ch0",
    "ch5",
    "CH1",
    "ch1 ",
    "ch1\n",
    "all,ch1",
    "../../etc/passwd",
    "ünïcødé ☃",
    "x" * 10**4,
    "-1",
)
# Options that are valid (used with a bad chapter).
GOOD_OPTIONS = ((), ("--full",), ("--workers", "1"), ("--dask", "local"), ("--json",))
# Options each invalid on its own (used with a valid chapter).
BAD_OPTIONS = (
    ("--workers", "0"),
    ("--workers", "-1"),
    ("--workers", "abc"),
    ("--workers", ""),
    ("--dask", "nope"),
    ("--dask", ""),
    ("--dask", "tcp://127.0.0.1:9"),  # nothing listens on the discard port
    ("--bogus",),
    ("--full", "yes"),  # an extra positional argument
)


@dataclass(frozen=True)
class ReproduceCase:
    """A bad chapter with valid options and any --out, or a chapter with one bad option."""

    chapter: str
    options: tuple[str, ...]
    out: str = "out"

    def __post_init__(self) -> None:  # never a real reproduction
        assert self.chapter not in VALID_CHAPTERS or (
            self.options in BAD_OPTIONS and self.out == "out"
        ), self


def reproduce_cases() -> st.SearchStrategy[ReproduceCase]:
    return st.one_of(
        st.builds(ReproduceCase, st.sampled_from(BAD_CHAPTERS), st.sampled_from(GOOD_OPTIONS),
                  st.sampled_from(OUT_VARIANTS)),
        st.builds(ReproduceCase, st.sampled_from(VALID_CHAPTERS), st.sampled_from(BAD_OPTIONS)),
    )  # fmt: skip


@pytest.mark.slow
@FUZZ_SETTINGS
@given(case=reproduce_cases())
@example(case=ReproduceCase("ch9", ()))
@example(case=ReproduceCase("ch1", ("--dask", "tcp://127.0.0.1:9")))
def test_reproduce_refuses_bad_arguments(fuzz: Fuzz, case: ReproduceCase):
    folder = fuzz.workdir()
    out = prepare_out(folder, case.out)
    args = ["reproduce", case.chapter, "--out", case.out, *case.options]
    change = f"chapter {case.chapter!r}, options {case.options}, --out {case.out!r}"
    example = Example("reproduce", args, folder, out, "--json" in case.options, mutation=change)
    outcome = fuzz.check(example, timeout=30)
    assert outcome.status == 2, f"bad arguments accepted: articula {' '.join(args)}"
