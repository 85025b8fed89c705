"""A gain sweep on a local Dask cluster that resumes: finished runs are never computed again.

The sweep is defined in Python as a sweep file would define it: a [base] config of the
experiment `pneunet.pid` (chapter 2: an ordinary PID, Eqs. 2.2-2.3, tracking the 0.2 Hz
sinusoid of Table 2.3 on 10 simulated PneuNets) and a [grid] over K_p and K_i (dotted keys into
the base's gain row). `run_sweep` runs it on a Dask LocalCluster of two worker processes,
started once and joined by its address (`articula sweep --dask tcp://HOST:PORT` does the same;
`--dask local` starts a cluster per sweep). Each run lands in OUT/sweep/HASH/ (config.toml,
record.json, trace.parquet; HASH names its full config) and the table of all runs in
OUT/sweep/results.parquet. The script sweeps a 3 × 3 grid, then the 4 × 4 grid that contains it
(only the 7 new points run), then the 4 × 4 grid again (nothing runs), and prints the table of
median tracking error E (Eq. 2.7).

    .venv/bin/python examples/08_dask_sweep.py [--quick] [--out DIR]

Run it again with the same --out and every pass finds its runs finished.
"""

import argparse
import os
import time
from pathlib import Path

import numpy as np
from distributed import LocalCluster
from matplotlib.figure import Figure

from articula.runs.runner import run_sweep
from articula.runs.sweep import expand_sweep

KP = "controller.gains.0.0"  # the dotted key of K_p in the base's row [K_p, K_i, K_d]
KI = "controller.gains.0.1"
BASE = {
    "experiment": "pneunet.pid",
    "seed": 0,
    "duration": 10.0,  # [s]
    "reference": {"kind": "sinusoid", "offset_deg": 45.0, "amplitude_deg": 45.0, "frequency": 0.2},
    "controller": {"schedule": "constant", "gains": [[1.0, 1.0, 0.0]]},
}


def sweep(spec, folder, scheduler):
    """Run a sweep on the Dask cluster at `scheduler`; report what ran; return its rows."""
    configs = expand_sweep(spec)
    finished = []  # the first progress call tells how many runs were already finished
    start = time.perf_counter()
    table = run_sweep(configs, folder, dask=scheduler,
                      progress=lambda done, total: finished.append(done))  # fmt: skip
    seconds = time.perf_counter() - start
    print(f"{len(configs):3d} runs: {len(configs) - finished[0]:2d} computed, "
          f"{finished[0]:2d} already finished ({seconds:4.1f} s)")  # fmt: skip
    return table.to_pylist()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 trials a run, 2 × 2 then 3 × 3")
    parser.add_argument("--out", type=Path, default=Path("example_output/08_dask_sweep"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    kp, ki = [1.0, 2.0, 4.0, 8.0], [8.0, 16.0, 32.0, 64.0]  # [counts/°], [counts/(°·s)]
    if args.quick:
        kp, ki = kp[:3], ki[:3]
    spec = {"base": BASE | {"trials": 5 if args.quick else 10}}
    folder = args.out / "sweep"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:  # fmt: skip
        print(f"Dask cluster: {len(cluster.workers)} worker processes")
        scheduler = cluster.scheduler_address  # tcp://127.0.0.1:<port>
        sweep(spec | {"grid": {KP: kp[:-1], KI: ki[:-1]}}, folder, scheduler)
        sweep(spec | {"grid": {KP: kp, KI: ki}}, folder, scheduler)  # grown by one value each
        rows = sweep(spec | {"grid": {KP: kp, KI: ki}}, folder, scheduler)  # again: all done
    runs = [p for p in folder.iterdir() if p.is_dir()]
    files = ", ".join(sorted(p.name for p in runs[0].iterdir()))
    print(f"{os.path.relpath(folder)}: results.parquet and {len(runs)} run folders of {files}\n")

    print(f"{'K_p':>5}{'K_i':>6}{'E median':>10}{'E Q1':>7}{'E Q3':>7}{'M median':>10}")
    for r in rows:
        print(f"{r[KP]:5.1f}{r[KI]:6.1f}{r['error_median_deg']:10.2f}{r['error_q1_deg']:7.2f}"
              f"{r['error_q3_deg']:7.2f}{r['cost_median']:10.1f}")  # fmt: skip
    print("E: Eq. (2.7) [°] over the trials; M: Eq. (2.5), median over the trials")

    error = np.array([[r["error_median_deg"] for r in rows if r[KP] == p] for p in kp])
    fig = Figure(figsize=(6, 4.8), layout="constrained")
    ax = fig.subplots()
    image = ax.imshow(error, origin="lower", cmap="viridis")
    for (i, j), value in np.ndenumerate(error):  # dark text on the light (high) cells
        color = "k" if value > error.mean() else "w"
        ax.text(j, i, f"{value:.1f}", ha="center", va="center", color=color, fontsize=9)
    ax.set_xticks(range(len(ki)), [f"{v:g}" for v in ki])
    ax.set_yticks(range(len(kp)), [f"{v:g}" for v in kp])
    ax.set_xlabel("K_i [PWM counts/(°·s)]")
    ax.set_ylabel("K_p [PWM counts/°]")
    ax.set_title("PneuNet, 0.2 Hz sinusoid: median E per (K_p, K_i)")
    fig.colorbar(image, label="median E, Eq. (2.7) [°]")
    path = args.out / "sweep.png"
    fig.savefig(path, dpi=110)
    print(f"figure: {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
