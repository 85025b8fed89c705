"""Success rates of articula's arm controllers beside mink's on generated problems (issue 13).

    python benchmarks/suite.py [--json] [--problems N] [--out DIR] [--problem-class CLASS]
                                                                     (needs '.[peers]')

Runs `articula bench suite` (articula/bench/suite.py) with seed 0 for two arms: the built-in
iiwa14, and the Franka Panda of pybullet_data (its URDF, package folder, the finger joints
locked at 0.02 m). Per arm and method: success rate, median step time [µs], and the success
rate less the better mink's (mink with its default collision gain, or with one matched to the
qp's dampers). Keys: <arm>_<method>_success (arm iiwa14 | panda, method with "-" as "_"),
<arm>_<method>_step_us (median), <arm>_<method>_mean_step_us, <arm>_<method>_vs_best_mink,
<arm>_<method>_step_time_vs_mink (mean step time over mink's); the folders stay under --out
(default: a temporary folder) with every problem as a scene file. --problem-class tight:
obstacles 2-5 cm from where the links pass; grazing: within d_min of it (bench/problems.py).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path
from typing import Any

from common import run

from articula.bench.problems import CLASSES
from articula.bench.suite import ARTICULA_METHODS, PEER_METHODS, peers_missing, run_suite

ARMS = ("iiwa14", "panda")


def panda_table() -> dict[str, Any]:
    """The [robot] table of pybullet_data's Panda with its fingers locked."""
    import pybullet_data

    folder = Path(pybullet_data.getDataPath()) / "franka_panda"
    return {"urdf": str(folder / "panda.urdf"), "package_dirs": [str(folder)],
            "locked_joints": {"panda_finger_joint1": 0.02}}  # fmt: skip


def measure(problems: int, out: str | None, problem_class: str) -> dict[str, Any]:
    """Both suites' summaries, flattened to the keys of the module's docstring."""
    root = Path(out or tempfile.mkdtemp(prefix="articula-suite-"))
    robots = {"iiwa14": {"builtin": "iiwa14"}, "panda": panda_table()}
    methods = list(ARTICULA_METHODS + PEER_METHODS)
    m: dict[str, Any] = {"problems": problems, "folder": str(root), "class": problem_class}
    for arm, table in robots.items():
        summary = run_suite(table, problems, 0, root / arm, methods, workers=2,
                            problem_class=problem_class)  # fmt: skip
        for method, s in summary["methods"].items():
            key = f"{arm}_{method.replace('-', '_')}"
            m[f"{key}_success"] = s["success_rate"]
            m[f"{key}_step_us"] = s["median_step_us"]
            m[f"{key}_mean_step_us"] = s["mean_step_us"]
            m[f"{key}_failures"] = s["failures"]
            for ratio in ("vs_best_mink", "step_time_vs_mink"):
                if ratio in s:
                    m[f"{key}_{ratio}"] = s[ratio]
    return m


def table(m: dict[str, Any]) -> tuple[str, list[str], list[list[str]]]:
    """One row per method: success and median step time on each arm."""
    rows = []
    for method in ARTICULA_METHODS + PEER_METHODS:
        key = method.replace("-", "_")
        row = [method]
        for arm in ARMS:
            row += [f"{100 * m[f'{arm}_{key}_success']:.0f} %",
                    f"{m[f'{arm}_{key}_step_us']:.0f}"]  # fmt: skip
        rows.append(row)
    title = (
        f"{m['problems']} generated {m['class']} problems per arm (seed 0); median µs per "
        f"period; folders in {m['folder']}"
    )
    return title, ["method", "iiwa14", "µs", "panda", "µs"], rows


def main() -> None:
    """Refuse to start without mink, then run."""
    missing = peers_missing()
    if missing:
        print(f"error: {missing}", file=sys.stderr)
        raise SystemExit(2)
    run(__doc__, measure, table,
        problems={"type": int, "default": 100, "help": "problems per arm"},
        out={"default": None, "help": "keep the suite folders here"},
        problem_class={"default": "standard", "choices": CLASSES,
                       "help": "the problems' class"})  # fmt: skip


if __name__ == "__main__":
    main()
