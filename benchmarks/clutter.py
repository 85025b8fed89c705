"""A cluttered cell: each controller's step time with 50 obstacles against the book's 2 (issue 31).

    python benchmarks/clutter.py [--json] [--steps N]      (needs pip install -e '.[peers]')

Scenes: book/ch1/configs/circle_two_obstacles.toml (iiwa14, the bracket and the rock, the
circle of Eq. 1.27 from home; the controllers of benchmarks/peers.py with its settings) and
the same with 48 more obstacles as a perception pipeline would hand them over: 24 boxes
(sides 3-12 cm) and 24 convex meshes (hulls of 32 points on ellipsoids of 3-8 cm semi-axes),
at random poses (seed 0) within CELL_RADIUS of the base, each at least CLEAR from every link
over the three controllers' motions in the two-obstacle scene (a pilot race), so the same
motion stays open, and many within the arm's reach. The controllers then step round-robin on
both scenes in one race (every lane one period in turn, the order rotating), each period
timed alone:
  <name>_step_us_2, <name>_step_us_50   median µs per period with 2 and with 50 obstacles
  <name>_clutter_ratio                  their ratio (targets: qp ≤ 2, improved ≤ 3)
  <name>_rms_m_50                       RMS error [m] after settle_s with 50 obstacles
  <name>_min_clearance_m_50             smallest articula clearance [m] with 50 obstacles
  clutter_distance_m                    the least distance of an added obstacle to the
                                        pilot motions [m]
  clutter_within_reach                  how many added obstacles are within 1.0 m of the
                                        shoulder
"""

from __future__ import annotations

import statistics
import sys
from typing import Any

import numpy as np
from common import run
from peers import INSTALL, SHOULDER, BookRace, _race, check_steps, with_obstacles

from articula.geometry.poses import pose
from articula.geometry.shapes import box, convex_hull
from articula.scene.obstacles import Obstacle
from articula.scene.scene import Scene

ADDED = 48  # obstacles added to the book's two: 50 in the cell
CELL_RADIUS = 1.3  # [m] from the base axis
CLEAR = 0.2  # [m] from every link over the pilot motions
NAMES = ("qp", "improved", "mink")


def measure(steps: int) -> dict[str, Any]:
    """Run the pilot and the race and return the measures (see the module's docstring)."""
    check_steps(steps)
    race = BookRace.load()
    scene, dt = race.scene, race.dt
    reference = race.reference(steps)
    pilot = race.lanes(scene)
    _race(pilot, reference)
    motion = [q for lane in pilot for q in lane.qs[::10]]
    cluttered, distance = with_clutter(scene, motion)
    lanes = race.lanes(scene, "_2") + race.lanes(cluttered, "_50")
    _race(lanes, reference)

    settle = min(5.0, steps * dt / 2)
    settled = np.arange(steps) * dt >= settle
    within = sum(np.linalg.norm(o.pose[:3, 3] - SHOULDER) < 1.0 for o in cluttered.obstacles[2:])
    m: dict[str, Any] = {"steps": steps, "dt_s": dt, "settle_s": settle, "obstacles": 50,
                         "clutter_distance_m": distance,
                         "clutter_within_reach": int(within)}  # fmt: skip
    by_name = {lane.name: lane for lane in lanes}
    for name in NAMES:
        for count in (2, 50):
            m[f"{name}_step_us_{count}"] = (
                statistics.median(by_name[f"{name}_{count}"].times_ns) / 1e3
            )
        m[f"{name}_clutter_ratio"] = m[f"{name}_step_us_50"] / m[f"{name}_step_us_2"]
        q = np.array(by_name[f"{name}_50"].qs)
        x = np.array([scene.robot.ee_position(qn) for qn in q])
        error = np.linalg.norm(x - reference, axis=1)
        m[f"{name}_rms_m_50"] = float(np.sqrt(np.mean(error[settled] ** 2)))
        m[f"{name}_min_clearance_m_50"] = float(min(cluttered.min_distance(qn) for qn in q[::5]))
    return m


def with_clutter(scene: Scene, motion: list[np.ndarray]) -> tuple[Scene, float]:
    """`scene` with ADDED boxes and convex meshes (alternating), each CLEAR from every link
    over `motion`, placed by a seeded search; and the least such distance [m]."""
    rng = np.random.default_rng(0)
    added: list[Obstacle] = []
    least = np.inf
    while len(added) < ADDED:
        k = len(added)
        if k % 2 == 0:
            shape = box(tuple(rng.uniform(0.03, 0.12, 3)))
        else:
            points = rng.standard_normal((32, 3))
            points *= rng.uniform(0.03, 0.08, 3) / np.linalg.norm(points, axis=1, keepdims=True)
            shape = convex_hull(points, f"clutter mesh {k}")
        radius, angle = CELL_RADIUS * np.sqrt(rng.random()), rng.uniform(0.0, 2 * np.pi)
        centre = [radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0.0, 1.3)]
        candidate = Obstacle(f"clutter{k}", (shape,), pose(centre, rng.uniform(-np.pi, np.pi, 3)))
        alone = Scene(scene.robot, (candidate,))
        closest = min(alone.min_distance(q) for q in motion)
        if closest >= CLEAR:
            added.append(candidate)
            least = min(least, closest)
    return with_obstacles(scene, added), float(least)


def table(m: dict[str, Any]) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        [
            label,
            f"{m[f'{name}_step_us_2']:.0f}",
            f"{m[f'{name}_step_us_50']:.0f}",
            f"{m[f'{name}_clutter_ratio']:.2f}",
            f"{1e6 * m[f'{name}_rms_m_50']:.3g}",
            f"{1e3 * m[f'{name}_min_clearance_m_50']:.1f}",
        ]
        for name, label in (("qp", "qp"), ("improved", "baornn-improved"), ("mink", "mink"))
    ]
    title = (
        f"one 10 ms period, median of {m['steps']}: 2 obstacles against 50 "
        f"({m['clutter_within_reach']} of the 48 added within 1 m of the shoulder, ≥ "
        f"{m['clutter_distance_m']:.2f} m from the links); RMS after {m['settle_s']:g} s"
    )
    columns = ["controller", "µs, 2", "µs, 50", "ratio", "RMS µm, 50", "clear. mm, 50"]
    return title, columns, rows


def main() -> None:
    """Refuse to start without mink, then run."""
    try:
        import mink  # noqa: F401
        import mujoco  # noqa: F401
    except ImportError as exc:
        print(f"error: {exc.name} is not installed; {INSTALL}", file=sys.stderr)
        raise SystemExit(2) from None
    steps = {"type": int, "default": 1000, "help": "control periods of the race"}
    run(__doc__, measure, table, steps=steps)


if __name__ == "__main__":
    main()
