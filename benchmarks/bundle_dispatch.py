"""Cost of handing the compiled clearance's arrays to a kernel from Python, by form.

    python benchmarks/bundle_dispatch.py [--json]

numba's dispatcher types every argument of every call from Python. The clearance's inputs
(scene/compiled_bundles.py: Chain, Shapes, Scratch and the pair rows, 24 arrays on the
iiwa14 scene of book/ch1/configs/circle_two_obstacles.toml) reach a kernel that reads one
number from them in three forms, median over 20000 calls each:
  packed_us   plain nested tuples, named again inside the kernel (what articula passes)
  named_us    the NamedTuple bundles themselves
  flat_us     24 arrays as separate arguments (the form before the bundles)
  named_over_packed   named_us / packed_us
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

import numpy as np
from common import run
from numba import njit

from articula.book.study import packaged
from articula.planning.objective import Objective
from articula.scene.compiled_bundles import Chain, ClearanceInputs, Scratch, Shapes, named_inputs
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

CALLS = 20000


@njit
def _from_packed(q, inputs, static_min):
    """The number of pairs, named inside."""
    return named_inputs(inputs).pairs.shape[0]


@njit
def _from_named(q, inputs, static_min):
    """The number of pairs of a ClearanceInputs."""
    return inputs.pairs.shape[0]


@njit
def _from_flat(q, *arrays):
    """The number of pairs, the second last of 25 arguments."""
    return arrays[-2].shape[0]


def measure() -> dict[str, float]:
    path = packaged("ch1", "circle_two_obstacles.toml")
    scene, q0 = build_scene(load_scene_spec(load_toml(path)), path.parent)
    compiled = Objective(scene, 0.005, 1.0, 0.002).compiled
    q, packed, static_min = np.asarray(q0, float), compiled.inputs(), compiled.static_min
    chain, shapes, scratch, pairs = packed
    named = ClearanceInputs(Chain(*chain), Shapes(*shapes), Scratch(*scratch), pairs)
    flat = (*chain, *shapes, *scratch, pairs, static_min)
    m = {
        "packed_us": _median_us(_from_packed, q, packed, static_min),
        "named_us": _median_us(_from_named, q, named, static_min),
        "flat_us": _median_us(_from_flat, q, *flat),
    }
    m["named_over_packed"] = m["named_us"] / m["packed_us"]
    return m


def _median_us(call: Callable[..., object], *args: object) -> float:
    """Median wall time of one call [µs], after warming up (compiling) it."""
    call(*args)
    times = []
    for _ in range(CALLS):
        start = time.perf_counter_ns()
        call(*args)
        times.append(time.perf_counter_ns() - start)
    return statistics.median(times) / 1e3


def table(m: dict[str, float]) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        ["packed: plain tuples, named inside (articula)", f"{m['packed_us']:.2f}"],
        ["named: the NamedTuple bundles", f"{m['named_us']:.2f}"],
        ["flat: 24 arrays as arguments", f"{m['flat_us']:.2f}"],
        ["named / packed", f"{m['named_over_packed']:.2f}×"],
    ]
    return f"one call from Python, median of {CALLS}", ["form", "µs"], rows


if __name__ == "__main__":
    run(__doc__, measure, table)
