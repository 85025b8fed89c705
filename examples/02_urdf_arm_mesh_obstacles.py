"""Your own arm from a URDF among mesh obstacles, built in Python (chapter 1, Sects. 1.2-1.3).

The arm is read from a URDF file by path, as you would read your own (here the iiwa14's file
shipped with articula), and you name the link whose origin is the end effector. Two obstacles
are written as STL files with trimesh, a pillar (a box) and an irregular convex rock, and
placed beside the forearm and above the elbow; each link and each obstacle is a convex hull, and
the distances between them are GJK distances (Sect. 1.3.3). The arm tracks a vertical circle
with baornn-improved twice: with Λ = 0, where only the hard constraint d_i > d_min of
Eq. (1.12) keeps the links away, and with Λ = 0.005, where the penalty of Eq. (1.11) also
pushes them off. The script prints each link's smallest distance to an obstacle over the run
and whether the hard minimum distance held.

    .venv/bin/python examples/02_urdf_arm_mesh_obstacles.py [--quick] [--out DIR]
"""

import argparse
import os
from importlib import resources
from pathlib import Path

import numpy as np
import trimesh
from matplotlib.figure import Figure

from articula.geometry.meshes import convex_parts, load_mesh
from articula.geometry.poses import pose
from articula.loops.tracking import track, tracking_metrics
from articula.planning.config import PlannerSpec, make_planner
from articula.planning.trajectories import Circle
from articula.robots import RobotModel
from articula.scene import Obstacle, Scene

URDF = Path(str(resources.files("articula") / "robots/data/iiwa14/iiwa14.urdf"))
D_MIN = 0.03  # [m] the hard minimum distance of Eq. (1.12)
LAMBDAS = (0.0, 0.005)  # Λ of Eq. (1.11)
SETTLE = 2.0  # [s] errors are taken after the approach to the circle


def write_meshes(folder, rng):
    """A 12 × 12 × 50 cm box and a rock (the hull of 40 random points) as STL files [m]."""
    trimesh.creation.box((0.12, 0.12, 0.5)).export(folder / "pillar.stl")
    directions = rng.normal(size=(40, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    points = directions * [0.09, 0.07, 0.05] * rng.uniform(1.0, 1.3, size=(40, 1))
    trimesh.convex.convex_hull(points).export(folder / "rock.stl")
    return {"pillar": folder / "pillar.stl", "rock": folder / "rock.stl"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="8 s instead of 20 s")
    parser.add_argument("--out", type=Path, default=Path("example_output", Path(__file__).stem))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    # The URDF's relative mesh paths start at its folder; for package:// ones, pass the folders
    # holding the packages as package_dirs=[...]. ee_frame names the end-effector link (default:
    # the last link); ee_offset=pose([0, 0, 0.1]) would put the tool point 10 cm beyond it.
    robot = RobotModel.from_urdf(URDF, ee_frame="iiwa_link_ee")
    meshes = write_meshes(args.out, np.random.default_rng(0))
    poses = {"pillar": pose([0.35, -0.30, 0.25]), "rock": pose([0.25, 0.0, 0.95], [0.3, 0, 0.5])}
    obstacles = [
        Obstacle(name, tuple(convex_parts(load_mesh(path), name)), poses[name])
        for name, path in meshes.items()
    ]
    scene = Scene(robot, obstacles)
    q0 = np.array([0.0, 0.6, 0.0, -1.2, 0.0, 0.8, 0.0])  # [rad] clear of both obstacles
    circle = Circle.create([0.55, 0.0, 0.45], [0, 1, 0], [0, 0, 1], radius=0.18, period=10.0)
    duration = 8.0 if args.quick else 20.0  # [s]
    print(f"{robot.nq} joints from {URDF.name}; end effector {robot.ee_frame}; "
          f"obstacles {', '.join(meshes)} (STL in {args.out.name}/)")  # fmt: skip

    runs, metrics = {}, {}
    for lam in LAMBDAS:
        spec = PlannerSpec(method="baornn-improved", lambda_weight=lam, d_min=D_MIN)
        planner = make_planner(spec, scene, seed=0)
        runs[lam] = track(planner, circle, q0, spec.dt, duration)
        metrics[lam] = tracking_metrics(runs[lam], robot, SETTLE, planner.iterations)
    # Each link's distance to each obstacle every 5th period (50 ms), the smallest of the run.
    per_link = {
        lam: np.stack([scene.distances(q) for q in run.q[::5]]).min(axis=0)
        for lam, run in runs.items()
    }

    names = [link.name for link in robot.links]
    print(f"\n{'link':<14}" + "".join(f"{f'Λ = {lam:g}: min [mm]':>22}{'closest':>9}"
                                      for lam in LAMBDAS))  # fmt: skip
    for i, name in enumerate(names):
        print(f"{name:<14}" + "".join(f"{1e3 * d[i].min():>22.1f}{obstacles[d[i].argmin()].name:>9}"
                                      for d in per_link.values()))  # fmt: skip
    print(f"\n{'Λ':<8}{'min clearance [mm]':>20}{f'> d_min = {1e3 * D_MIN:g} mm':>18}"
          f"{'RMS error [mm]':>16}")  # fmt: skip
    for lam, m in metrics.items():
        held = "held" if m["min_clearance"] > D_MIN else "broken"
        print(f"{lam:<8g}{1e3 * m['min_clearance']:>20.2f}{held:>18}{1e3 * m['rms_error']:>16.3f}")
    print(f"(RMS error after the first {SETTLE:g} s of {duration:g} s)")

    fig = Figure(figsize=(12, 4.2), layout="constrained")
    bars, clearance = fig.subplots(1, 2)
    x = np.arange(len(names))
    for k, (lam, d) in enumerate(per_link.items()):
        colour = f"C{k}"
        bars.bar(x + 0.4 * k - 0.2, 1e3 * d.min(axis=1), 0.4, color=colour, label=f"Λ = {lam:g}")
        clearance.plot(runs[lam].t, 1e3 * runs[lam].clearance, color=colour, label=f"Λ = {lam:g}")
    for ax in (bars, clearance):
        ax.axhline(1e3 * D_MIN, color="tab:red", ls=":", label="d_min")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    bars.set_xticks(x, [name.removeprefix("iiwa_") for name in names], rotation=30)
    bars.set(ylabel="min distance to an obstacle [mm]", title="each link, over the run")
    clearance.set(xlabel="t [s]", ylabel="min link-obstacle distance [mm]", title="clearance")
    clearance.set_ylim(bottom=0)
    path = args.out / "clearance.png"
    fig.savefig(path, dpi=120)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
