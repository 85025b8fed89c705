"""articula's arm controllers beside mink, in one process, same arm and obstacles (issue 13).

    python benchmarks/peers.py [--json] [--steps N]      (needs pip install -e '.[peers]')

Scene: book/ch1/configs/circle_two_obstacles.toml (iiwa14, the bracket and the rock as
convex hulls, the circle of Eq. 1.27 from the home position, the scene's [planner] table).
Three controllers run one 10 ms control period per call, with the scene's d_min = 0.002 m,
detection distance 0.15 m (articula's influence), the URDF's joint speed limits and a
position task on the end effector:
  qp          articula's OnlineController, method "qp" (NEO-style dampers solved by daqp;
              its dampers stop at articula's default safety distance, 0.03 m)
  improved    articula's OnlineController, method "baornn-improved" (the scene's Λ, c1, c2,
              d_min as its hard minimum distance)
  mink        articula/bench/mink_peer.py: mink.solve_ik (daqp) with a FrameTask on the
              end-effector site, ConfigurationLimit, VelocityLimit and
              CollisionAvoidanceLimit (minimum distance d_min, mink's default gain 0.85)
              between every link hull and every obstacle hull, the same hulls as articula's
              (MuJoCo mesh geoms)
and, for the record, mink_matched: mink with its collision gain turned into a damper like the
qp's. mink bounds a displacement Δq by gain (d − d_min) / dt, so the default gain lets a pair
close 85 (d − d_min) in one 10 ms period: the bound holds only once d ≤ d_min, and a link
moving fast goes through it (here the forearm into the bracket). gain = dt² · 1 m/s /
(detection − d_min) is the qp's damper rate [1/s] in those units.

The controllers step round-robin, one period each in turn (the order rotating every period),
so that machine noise hits all alike; every period is timed alone (perf_counter_ns around the
call):
  <name>_step_us              median µs per control period
  qp_vs_mink, improved_vs_mink  ratios of those medians (> 1: articula slower)
  <name>_rms_m, _max_error_m  RMS and largest distance [m] of the end effector from the
                              reference after settle_s = min(5 s, half the run)
  <name>_min_clearance_m      smallest articula Scene.min_distance [m] over the run (mink's q
                              measured by articula's scene too)
  <name>_far_step_us          median µs per period with 0, 1, 2, 4, 8 far obstacles
                              (half-size rock copies 2 m from the base axis, farther than the
                              detection distance from every link over the whole motion:
                              far_min_distance_m), from a second round-robin race of all
                              controllers on all those scenes, far_steps periods
  <name>_per_far_obstacle_us  least-squares slope of those medians over the count
  <name>_near_step_us         the same with 0, 1, 2, 4, 8 near obstacles: half-size rock
                              copies within the arm's reach, 0.3-0.6 m from every link over
                              every controller's motion of the main race (near_distance_m:
                              the least and largest such distance), outside the detection
                              distance: a cell's objects that no method needs to avoid
  <name>_per_near_obstacle_us least-squares slope of those medians over the count (issue 31's
                              target: ≤ 10 µs for qp and improved)
mink checks its pairs one by one below 16 pairs (the two obstacles make 14) and with a
vectorized bounding-sphere broad phase from 16 on, so its cost steps up from 0 to 1 far
obstacle and is nearly flat after.
"""

from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from common import run

from articula.book.study import packaged
from articula.experiments.plan import build_plan
from articula.geometry.shapes import convex_hull
from articula.loops.online import OnlineController
from articula.planning.config import PlannerSpec
from articula.scene.obstacles import Obstacle
from articula.scene.scene import Scene
from articula.validation import load_toml

SCENE = "circle_two_obstacles.toml"
INFLUENCE = 0.15  # [m] articula's qp influence distance = mink's collision_detection_distance
FAR_COUNTS = (0, 1, 2, 4, 8)
FAR_RADIUS = 2.0  # [m] from the base axis; the iiwa14 reaches about 1.3 m
NEAR_COUNTS = FAR_COUNTS
NEAR_BAND = (0.3, 0.6)  # [m] from every link over the main race's motions
SHOULDER = np.array([0.0, 0.0, 0.36])  # [m] the iiwa14's second joint: the centre of reach
FAR_STEPS = 300  # periods of the far-obstacle race (fewer when --steps is smaller)
WARMUP = 5  # periods run (and discarded) by each controller before the race: JIT, caches
NAMES = ("qp", "improved", "mink")
INSTALL = "pip install -e '.[peers]'"


@dataclass
class Lane:
    """One controller in a race: its step function, and what its periods did."""

    name: str
    step: Callable[[np.ndarray], np.ndarray]
    times_ns: list[int] = field(default_factory=list)
    qs: list[np.ndarray] = field(default_factory=list)


@dataclass(frozen=True)
class BookRace:
    """The book's two-obstacle circle as the races run it: the scene, the start, articula's
    controllers' settings (speed limits, INFLUENCE) and the reference.

    Attributes:
        scene: the iiwa14 and the bracket and rock.
        q0: the start, shape (7,) [rad].
        specs: "qp" and "improved" -> their [planner] settings.
        seed: the scene file's seed.
        targets: the reference, t [s] -> target.
    """

    scene: Scene
    q0: np.ndarray
    specs: dict[str, PlannerSpec]
    seed: int
    targets: Callable[[float], Any]

    @classmethod
    def load(cls) -> BookRace:
        """The packaged circle_two_obstacles.toml, its planner with the speed limits."""
        path = packaged("ch1", SCENE)
        data = load_toml(path)
        table = {**data["planner"], "limits": "velocity", "influence": INFLUENCE}
        plan = build_plan({**data, "planner": table}, path.parent, str(path))
        specs = {name: PlannerSpec(**{**table, "method": method})
                 for name, method in (("qp", "qp"), ("improved", "baornn-improved"))}  # fmt: skip
        return cls(plan.scene, plan.q0, specs, plan.config.seed, plan.targets)

    @property
    def d_min(self) -> float:
        """The hard minimum distance [m]."""
        return self.specs["qp"].d_min

    @property
    def dt(self) -> float:
        """The control period [s]."""
        return self.specs["qp"].dt

    def reference(self, steps: int) -> np.ndarray:
        """The reference positions of the first `steps` periods, shape (steps, 3) [m]."""
        return np.array([self.targets(n * self.dt).position for n in range(steps)])

    def lanes(self, scene: Scene, suffix: str = "", gain: float | None = None) -> list[Lane]:
        """Warmed-up qp, improved and mink lanes on `scene` (their names ending in `suffix`),
        and mink_matched with the collision gain `gain` when one is given."""
        from articula.bench.mink_peer import MinkArm  # pip install -e '.[peers]'

        q0, d_min, dt = self.q0, self.d_min, self.dt
        out = [Lane(f"{name}{suffix}", _articula(scene, self.specs[name], self.seed, q0))
               for name in ("qp", "improved")]  # fmt: skip
        out.append(Lane(f"mink{suffix}", _mink(MinkArm(scene, d_min, INFLUENCE, dt), q0)))
        if gain is not None:
            arm = MinkArm(scene, d_min, INFLUENCE, dt, gain=gain)
            out.append(Lane(f"mink_matched{suffix}", _mink(arm, q0)))
        return out


def check_steps(steps: int) -> None:
    """Refuse fewer than two periods (exit 2, one line)."""
    if steps < 2:
        print("error: --steps must be at least 2", file=sys.stderr)
        raise SystemExit(2)


def measure(steps: int) -> dict[str, Any]:
    """Run the races and return the measures (see the module's docstring)."""
    from articula.bench.mink_peer import matched_gain  # pip install -e '.[peers]'

    check_steps(steps)
    race = BookRace.load()
    scene, d_min, dt = race.scene, race.d_min, race.dt
    reference = race.reference(max(steps, FAR_STEPS))
    # A damper like the qp's (1 m/s over the detection band) in mink's units.
    gain = matched_gain(dt, d_min, INFLUENCE)
    main = race.lanes(scene, gain=gain)
    _race(main, reference[:steps])
    far_steps = min(steps, FAR_STEPS)
    far_scenes = {n: with_far_obstacles(scene, n) for n in FAR_COUNTS}
    far = {n: race.lanes(s) for n, s in far_scenes.items()}
    _race([lane for n in FAR_COUNTS for lane in far[n]], reference[:far_steps])
    motion = [q for lane in main for q in lane.qs[::10]]
    near_scenes, near_distance = with_near_obstacles(scene, max(NEAR_COUNTS), motion)
    near = {n: race.lanes(near_scenes[n]) for n in NEAR_COUNTS}
    _race([lane for n in NEAR_COUNTS for lane in near[n]], reference[:far_steps])

    settle = min(5.0, steps * dt / 2)
    settled = np.arange(steps) * dt >= settle
    m: dict[str, Any] = {"steps": steps, "far_steps": far_steps, "dt_s": dt, "d_min_m": d_min,
                         "detection_m": INFLUENCE, "settle_s": settle,
                         "mink_matched_gain": gain,
                         "far_counts": list(FAR_COUNTS), "near_counts": list(NEAR_COUNTS),
                         "near_distance_m": near_distance}  # fmt: skip
    for lane in main:
        q = np.array(lane.qs)
        x = np.array([scene.robot.ee_position(qn) for qn in q])
        error = np.linalg.norm(x - reference[:steps], axis=1)
        m[f"{lane.name}_step_us"] = statistics.median(lane.times_ns) / 1e3
        m[f"{lane.name}_rms_m"] = float(np.sqrt(np.mean(error[settled] ** 2)))
        m[f"{lane.name}_max_error_m"] = float(error[settled].max())
        m[f"{lane.name}_min_clearance_m"] = float(min(scene.min_distance(qn) for qn in q))
    for name in ("qp", "improved"):
        m[f"{name}_vs_mink"] = m[f"{name}_step_us"] / m["mink_step_us"]
    counts = np.array(FAR_COUNTS, dtype=float)
    for k, name in enumerate(NAMES):
        medians = [statistics.median(far[n][k].times_ns) / 1e3 for n in FAR_COUNTS]
        m[f"{name}_far_step_us"] = medians
        m[f"{name}_per_far_obstacle_us"] = float(np.polyfit(counts, medians, 1)[0])
        medians = [statistics.median(near[n][k].times_ns) / 1e3 for n in NEAR_COUNTS]
        m[f"{name}_near_step_us"] = medians
        m[f"{name}_per_near_obstacle_us"] = float(np.polyfit(counts, medians, 1)[0])
    m["far_min_distance_m"] = far_clearance(far_scenes[max(FAR_COUNTS)], scene, main)
    return m


def _articula(scene: Scene, spec: PlannerSpec, seed: int, q0: np.ndarray):
    """A warmed-up OnlineController's step, reset to q0."""
    controller = OnlineController.from_spec(scene, spec, seed=seed)
    q = controller.reset(q0)
    for _ in range(WARMUP):
        controller.step(scene.robot.ee_position(q))
    controller.reset(q0)
    return controller.step


def _mink(arm, q0: np.ndarray):
    """A warmed-up MinkArm's step, reset to q0."""
    q = arm.reset(q0)
    for _ in range(WARMUP):
        arm.step(arm.scene.robot.ee_position(q))
    arm.reset(q0)
    return arm.step


def _race(lanes: Sequence[Lane], reference: np.ndarray) -> None:
    """Every lane tracks `reference` (one row per period), one period each in turn; the order
    rotates every period."""
    clock = time.perf_counter_ns
    n = len(lanes)
    for k, target in enumerate(reference):
        for i in range(n):
            lane = lanes[(i + k) % n]
            start = clock()
            q = lane.step(target)
            lane.times_ns.append(clock() - start)
            lane.qs.append(q)


def with_far_obstacles(scene: Scene, count: int) -> Scene:
    """`scene` with `count` half-size copies of its rock, FAR_RADIUS from the base axis at
    z = 0.5 m, evenly spread around it."""
    rock = next(o for o in scene.obstacles if o.name == "rock")
    small = tuple(convex_hull(0.5 * part.vertices, "far rock") for part in rock.parts)
    extra = []
    for k in range(count):
        angle = 2 * np.pi * k / max(count, 1) + 0.3
        pose = np.eye(4)
        pose[:3, 3] = [FAR_RADIUS * np.cos(angle), FAR_RADIUS * np.sin(angle), 0.5]
        extra.append(Obstacle(f"far{k}", small, pose))
    return with_obstacles(scene, extra)


def with_obstacles(scene: Scene, extra: Sequence[Obstacle]) -> Scene:
    """`scene` (its broad phase, metric and self pairs) with the `extra` obstacles added."""
    return Scene(scene.robot, (*scene.obstacles, *extra), scene.broadphase, scene.metric,
                 scene.self_pair_names)  # fmt: skip


def with_near_obstacles(
    scene: Scene, count: int, motion: Sequence[np.ndarray]
) -> tuple[dict[int, Scene], list[float]]:
    """`scene` with the first n of `count` half-size rock copies (n in NEAR_COUNTS), each
    NEAR_BAND from every link over `motion`, centres 0.3 m apart, placed by a seeded
    search within 1.2 m of the base; and the least and largest of their distances [m]."""
    rock = next(o for o in scene.obstacles if o.name == "rock")
    small = tuple(convex_hull(0.5 * part.vertices, "near rock") for part in rock.parts)
    rng = np.random.default_rng(0)
    placed: list[Obstacle] = []
    distances: list[float] = []
    while len(placed) < count:
        pose = np.eye(4)
        pose[:3, 3] = rng.uniform([-1.2, -1.2, 0.0], [1.2, 1.2, 1.4])
        if np.linalg.norm(pose[:3, 3] - SHOULDER) > 1.2 or any(
            np.linalg.norm(pose[:3, 3] - o.pose[:3, 3]) < 0.3 for o in placed
        ):
            continue
        candidate = Obstacle(f"near{len(placed)}", small, pose)
        alone = Scene(scene.robot, (candidate,))
        closest = min(alone.min_distance(q) for q in motion)
        if NEAR_BAND[0] <= closest <= NEAR_BAND[1]:
            placed.append(candidate)
            distances.append(closest)
    scenes = {n: with_obstacles(scene, placed[:n]) for n in NEAR_COUNTS}
    return scenes, [min(distances, default=0.0), max(distances, default=0.0)]


def far_clearance(far_scene: Scene, scene: Scene, lanes: Sequence[Lane]) -> float:
    """Smallest distance [m] from any link to any far obstacle over every lane's motion
    (every fifth period)."""
    n = len(scene.obstacles)
    qs = [q for lane in lanes for q in lane.qs[::5]]
    return float(min(far_scene.distances(q)[:, n:].min() for q in qs))


def table(m: dict[str, Any]) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = []
    for name, label in (("qp", "qp"), ("improved", "baornn-improved"), ("mink", "mink"),
                        ("mink_matched", f"mink {m['mink_matched_gain']:.1e}")):  # fmt: skip
        ratio = f"{m[f'{name}_step_us'] / m['mink_step_us']:.2f}"
        slope = m.get(f"{name}_per_far_obstacle_us")
        near = m.get(f"{name}_per_near_obstacle_us")
        rows.append(
            [
                label,
                f"{m[f'{name}_step_us']:.0f}",
                ratio,
                "" if slope is None else f"{slope:+.1f}",
                "" if near is None else f"{near:+.1f}",
                f"{1e6 * m[f'{name}_rms_m']:.3g}",
                f"{1e3 * m[f'{name}_min_clearance_m']:.2f}",
            ]
        )
    title = (
        f"one 10 ms period, median of {m['steps']} (far obstacles {m['far_counts']}: "
        f"{m['far_steps']} periods, ≥ {m['far_min_distance_m']:.2f} m away; near "
        f"{m['near_distance_m'][0]:.2f}-{m['near_distance_m'][1]:.2f} m); RMS after "
        f"{m['settle_s']:g} s"
    )
    columns = ["controller", "µs/period", "× mink", "µs/far obst.", "µs/near obst.", "RMS µm",
               "clear. mm"]  # fmt: skip
    return title, columns, rows


def main() -> None:
    """Refuse to start without mink, then run."""
    try:
        import mink  # noqa: F401
        import mujoco  # noqa: F401
    except ImportError as exc:
        print(f"error: {exc.name} is not installed; {INSTALL}", file=sys.stderr)
        raise SystemExit(2) from None
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    steps = {"type": int, "default": 1000, "help": "control periods of the main race"}
    run(__doc__, measure, table, steps=steps)


if __name__ == "__main__":
    main()
