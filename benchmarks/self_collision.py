"""The allowed-collision matrix of long chains: bounded, and kept on disk (issue 26 target: a
200-link chain's `scene check` in seconds).

    python benchmarks/self_collision.py [--json]

Chains of 25, 50, 100 and 200 boxes, 0.1 m apart on revolute joints about x and y in turn
(±2.6 rad, so that links far apart fold onto each other), 1000 samples, margin 0.02 m:
  <n>_cold_s         self_collision_matrix with an empty cache (the sphere bounds, then the
                     exact distances they leave, at most MAX_QUERIES)
  <n>_cached_s       the same call again: the matrix read from the disk cache
  <n>_checked        pairs checked
  <n>_brute_s        the baseline: every non-adjacent pair's exact distance at every sample
                     (25 and 50 links only; it grows with the square of the links)
  <n>_speedup        <n>_brute_s / <n>_cold_s
"""

from __future__ import annotations

import itertools
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from common import run

from articula.robots import RobotModel
from articula.scene import Scene
from articula.scene.self_collision import self_collision_matrix

SAMPLES = 1000


def chain(folder: Path, links: int) -> RobotModel:
    """A chain of `links` boxes on revolute joints about x and y in turn."""
    body = "".join(
        f'<link name="l{i}"><collision><origin xyz="0 0 0.05"/><geometry>'
        '<box size="0.03 0.03 0.09"/></geometry></collision></link>'
        for i in range(links)
    )
    body += "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0 0 0.1"/><axis xyz="{"0 1 0" if i % 2 else "1 0 0"}"/>'
        '<limit lower="-2.6" upper="2.6" effort="1" velocity="1"/></joint>'
        for i in range(links - 1)
    )
    path = folder / f"chain{links}.urdf"
    path.write_text(f'<robot name="chain">{body}</robot>')
    return RobotModel.from_urdf(path, max_links=links)


def brute_force(robot: RobotModel) -> None:
    """Every non-adjacent pair's exact distance at every sample, as the matrix was built."""
    names = [link.name for link in robot.links]
    pairs = [(a, b) for a, b in itertools.combinations(names, 2)
             if abs(names.index(a) - names.index(b)) > 1]  # fmt: skip
    scene = Scene(robot, [], self_pairs=pairs)
    for q in np.random.default_rng(0).uniform(*robot.sample_range, (SAMPLES, robot.nq)):
        scene.self_distances(q)


def measure() -> dict[str, float]:
    out: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as folder:
        os.environ["ARTICULA_CACHE_DIR"] = str(Path(folder) / "cache")
        for links in (25, 50, 100, 200):
            robot = chain(Path(folder), links)
            start = time.perf_counter()
            matrix = self_collision_matrix(robot, samples=SAMPLES)
            out[f"{links}_cold_s"] = time.perf_counter() - start
            start = time.perf_counter()
            self_collision_matrix(robot, samples=SAMPLES)
            out[f"{links}_cached_s"] = time.perf_counter() - start
            out[f"{links}_checked"] = len(matrix.checked)
            if links <= 50:
                start = time.perf_counter()
                brute_force(robot)
                out[f"{links}_brute_s"] = time.perf_counter() - start
                out[f"{links}_speedup"] = out[f"{links}_brute_s"] / out[f"{links}_cold_s"]
    return out


def table(m: dict[str, float]) -> tuple[str, list[str], list[list[str]]]:
    rows = []
    for links in (25, 50, 100, 200):
        brute = m.get(f"{links}_brute_s")
        rows.append([str(links), f"{m[f'{links}_cold_s']:.2f}", f"{m[f'{links}_cached_s']:.3f}",
                     str(int(m[f"{links}_checked"])), "—" if brute is None else f"{brute:.1f}",
                     "—" if brute is None else f"{m[f'{links}_speedup']:.0f}×"])  # fmt: skip
    return (
        "Allowed-collision matrix of a chain, 1000 samples",
        ["links", "cold [s]", "cached [s]", "checked", "brute force [s]", "speed-up"],
        rows,
    )


if __name__ == "__main__":
    run(__doc__, measure, table)
