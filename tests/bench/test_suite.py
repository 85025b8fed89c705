"""`articula bench suite`: every method on the same generated problems; results.parquet and
summary.json agree with each run's own criteria; finished problems are not run again."""

from __future__ import annotations

import importlib.util

import numpy as np
import pyarrow.parquet as pq
import pytest
import tomli_w

from articula.bench import suite
from articula.validation import load_toml
from tests.arms import jaco2_robot

PEERS = importlib.util.find_spec("mink") is not None and importlib.util.find_spec("mujoco")


def _check_rows(rows: list[dict]) -> None:
    """Each row's success and failure class follow from its own metrics (suite.FAILURES)."""
    for r in rows:
        if r["failure"] == "error":
            continue
        broken = [name for name, bad in (
            ("collision", r["colliding_steps"] > 0),
            ("joint_limits", r["joint_limit_steps"] > 0),
            ("speed_limits", r["max_speed_ratio"] > 1.0 + 1e-6),
            ("tracking", not r["rms_error"] < suite.SUCCESS_RMS),
        ) if bad]  # fmt: skip
        assert r["success"] == (not broken)
        assert r["failure"] == (broken[0] if broken else None)
        assert (r["colliding_steps"] > 0) == (r["min_clearance"] <= 0)


def test_a_suite_runs_every_method_on_every_problem_and_resumes(tmp_path, cli, one_json):
    out = tmp_path / "suite"
    args = ("bench", "suite", "--problems", "3", "--seed", "1", "--methods", "qp,pinv",
            "--workers", "1", "--out", out, "--json")  # fmt: skip
    proc = cli(*args)
    assert proc.returncode == 0, proc.stderr
    summary = one_json(proc.stdout)
    rows = pq.read_table(out / "results.parquet").to_pylist()
    assert sorted((r["problem"], r["method"]) for r in rows) == [
        (i, m) for i in range(3) for m in ("pinv", "qp")
    ]
    _check_rows(rows)
    for method in ("qp", "pinv"):
        mine = [r for r in rows if r["method"] == method]
        m = summary["methods"][method]
        assert m["successes"] == sum(r["success"] for r in mine)
        assert m["success_rate"] == pytest.approx(m["successes"] / 3)
        assert sum(m["failures"].values()) == 3 - m["successes"]
        assert m["min_clearance_m"] == pytest.approx(min(r["min_clearance"] for r in mine))
        assert 0 < m["median_step_us"] <= m["p99_step_us"]
    assert (out / "problems" / "002" / "scene.toml").is_file()
    # Again: nothing is run, the same table comes back.
    stamps = {p: p.stat().st_mtime_ns for p in (out / "problems").glob("*/results.json")}
    again = cli(*args)
    assert again.returncode == 0, again.stderr
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps
    assert pq.read_table(out / "results.parquet").to_pylist() == rows
    # Other methods are other results: every problem runs again.
    other = cli(*args[:7], "qp", *args[8:])
    assert other.returncode == 0, other.stderr
    assert all(p.stat().st_mtime_ns != t for p, t in stamps.items())


@pytest.mark.slow
@pytest.mark.skipif(not PEERS, reason="pip install -e '.[peers]'")
def test_mink_runs_the_same_problems(tmp_path):
    summary = suite.run_suite({"builtin": "iiwa14"}, 2, 0, tmp_path / "s",
                              ["qp", "mink", "mink-matched"])  # fmt: skip
    rows = pq.read_table(tmp_path / "s" / "results.parquet").to_pylist()
    _check_rows(rows)
    assert {r["method"] for r in rows} == {"qp", "mink", "mink-matched"}
    best = max(summary["methods"][m]["success_rate"] for m in ("mink", "mink-matched"))
    assert summary["methods"]["qp"]["vs_best_mink"] == pytest.approx(
        summary["methods"]["qp"]["success_rate"] - best
    )
    qp, mink = summary["methods"]["qp"], summary["methods"]["mink"]
    assert qp["step_time_vs_mink"] == pytest.approx(qp["mean_step_us"] / mink["mean_step_us"])


@pytest.mark.slow
def test_the_tight_class_is_its_own_suite(tmp_path, cli, one_json):
    out = tmp_path / "suite"
    args = ("bench", "suite", "--problems", "2", "--methods", "qp", "--workers", "1",
            "--out", out, "--json")  # fmt: skip
    tight = one_json(cli(*args, "--class", "tight").stdout)
    assert tight["class"] == "tight"
    first = (out / "problems" / "000" / "scene.toml").read_text()
    standard = one_json(cli(*args).stdout)  # another class: every problem again, regenerated
    assert standard["class"] == "standard"
    assert (out / "problems" / "000" / "scene.toml").read_text() != first


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    ("options", "named"),
    [
        (("--methods", "qp,warp"), "--methods"),
        (("--robot", "no_such_arm.urdf"), "--robot"),
        (("--problems", "0"), "--problems"),
        (("--class", "loose"), "--class"),
    ],
)
def test_bad_options_are_one_line_and_exit_2(tmp_path, cli, options, named):
    proc = cli("bench", "suite", "--out", tmp_path / "s", *options)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and named in proc.stderr


@pytest.mark.slow
def test_the_tight_suite_on_dask_gives_the_local_numbers(tmp_path):
    # Same problems, seed and methods: the rows do not depend on the backend.
    runs = {}
    for backend in (None, "local"):
        out = tmp_path / f"suite-{backend}"
        suite.run_suite({"builtin": "iiwa14"}, 2, 5, out, ["qp"], workers=1, dask=backend,
                        problem_class="tight")  # fmt: skip
        rows = pq.read_table(out / "results.parquet").to_pylist()
        runs[backend] = [{k: v for k, v in r.items() if not k.endswith("_us")} for r in rows]
    assert runs[None] == runs["local"] and len(runs[None]) == 2


def test_an_arm_with_continuous_joints_gets_starts_within_a_turn(tmp_path, cli, one_json):
    """Issue 48: the Jaco 2's continuous joints 1, 4 and 6 have ±inf limits, and starts drawn
    between them failed the suite ("Range exceeds valid bounds"); they are drawn over
    (−π, π]."""
    robot = {k: v for k, v in jaco2_robot().items() if k != "q0"}
    (tmp_path / "kinova.toml").write_text(tomli_w.dumps({"robot": robot}))
    out = tmp_path / "suite"
    proc = cli("bench", "suite", "--robot", tmp_path / "kinova.toml", "--problems", "2",
               "--methods", "qp", "--workers", "1", "--out", out, "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    summary = one_json(proc.stdout)
    assert summary["problems"] == 2 and summary["methods"]["qp"]["failures"]["error"] == 0
    for k in range(2):
        q0 = np.array(load_toml(out / "problems" / f"{k:03d}" / "scene.toml")["robot"]["q0"])
        assert np.all((-np.pi < q0[[0, 3, 5]]) & (q0[[0, 3, 5]] <= np.pi))
