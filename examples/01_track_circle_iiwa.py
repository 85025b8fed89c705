"""Chapter 1 in a few lines: the KUKA iiwa14 tracks the book's circle past two obstacles.

The built-in iiwa14 starts from its home position and follows the circle of Eq. (1.27) while
the objective of Eqs. (1.11)-(1.13) (Λ = 0.005, d_min = 2 mm) keeps every link away from a
bracket beside the forearm and a rock above the elbow (Sect. 1.4.3, Figs. 1.8 and 1.11-1.12).
The scene, the circle and the planner's parameters are the packaged scene file
src/articula/book/ch1/configs/circle_two_obstacles.toml, read through the library's config
API; BAORNN (Algorithm 1) and baornn-improved then track it from the same start, within the
arm's joint speed and acceleration limits (the defaults), the reference first moving from the
tool to the circle's start (the approach). The script prints the tracking error after the
settling time, the smallest link-obstacle (GJK) distance and the planner's time per 10 ms
period, and draws the end-effector path against the target and the clearance over time.

    .venv/bin/python examples/01_track_circle_iiwa.py [--quick] [--out DIR]
"""

import argparse
import os
from importlib import resources
from pathlib import Path

from matplotlib.figure import Figure

from articula.experiments.plan import build_plan
from articula.loops.tracking import track, tracking_metrics
from articula.validation import load_toml

SCENE_FILE = Path(str(resources.files("articula") / "book/ch1/configs/circle_two_obstacles.toml"))
ROW = "{:<16}{:>15}{:>15}{:>15}{:>13}"  # the printed table's columns
METHODS = {"baornn": "tab:orange", "baornn-improved": "tab:green"}  # method -> colour


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="8 s of the circle instead of 50 s")
    parser.add_argument("--out", type=Path, default=Path("example_output", Path(__file__).stem))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    # [robot], [[obstacles]], [trajectory], [planner]: the scene, its start q0, the circle and
    # the reference that first moves from the tool at home to the circle's start (the approach).
    plan = build_plan(load_toml(SCENE_FILE), SCENE_FILE.parent, str(SCENE_FILE))
    scene, q0, reference, book = plan.scene, plan.q0, plan.reference, plan.spec
    duration = 8.0 if args.quick else book.duration  # [s]; one lap takes 50 s
    settle = min(book.settle, duration / 2)  # [s] into the circle
    lead = reference.duration  # [s]

    runs = {}
    print(ROW.format("method", "RMS error [mm]", "max error [mm]", "clearance [mm]", "period [µs]"))
    for method in METHODS:
        planner = plan.planner(method)
        run = track(planner, reference, q0, book.dt, lead + duration, path_start=lead)
        m = tracking_metrics(run, scene.robot, settle, planner.iterations)
        mm = [f"{1e3 * m[k]:.3f}" for k in ("rms_error", "max_error", "min_clearance")]
        print(ROW.format(method, *mm, f"{m['time_per_period_us']:.0f}"))
        runs[method] = run
    print(f"errors after {settle:g} s of the {duration:g} s circle, which starts after a "
          f"{lead:.1f} s approach; clearance: smallest link-obstacle distance (d_min = "
          f"{1e3 * book.d_min:g} mm)")  # fmt: skip

    fig = Figure(figsize=(13, 4.2), layout="constrained")
    path, error, clearance = fig.subplots(1, 3, width_ratios=[1, 1.3, 1.3])
    reference = runs["baornn"].x_ref
    path.plot(reference[:, 0], reference[:, 2], "k--", lw=1, label="target")
    for method, colour in METHODS.items():
        run = runs[method]
        path.plot(run.x[:, 0], run.x[:, 2], color=colour, lw=1.2, label=method)
        error.semilogy(run.t, 1e3 * run.error, color=colour, lw=0.8, label=method)
        clearance.plot(run.t, 1e3 * run.clearance, color=colour, label=method)
    error.axvline(lead, color="grey", ls="--", label="the circle starts")
    error.axvline(lead + settle, color="grey", ls=":", label="settle")
    clearance.axhline(1e3 * book.d_min, color="tab:red", ls=":", label="d_min")
    path.set(xlabel="x [m]", ylabel="z [m]", title="end-effector path from home (y = 0.6 m)")
    path.set_aspect("equal")
    error.set(xlabel="t [s]", ylabel="tracking error [mm]", title="|x_r - f(θ)|")
    clearance.set(xlabel="t [s]", ylabel="min link-obstacle distance [mm]", title="clearance")
    clearance.set_ylim(bottom=0)
    for ax in (path, error, clearance):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    path = args.out / "circle.png"
    fig.savefig(path, dpi=120)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
