"""The dynamics twin's speed: simulated seconds per wall second, and the servo stream's cost.

    python benchmarks/twin.py [--json]

qp tracks the book's two-obstacle circle (book/ch1/configs/circle_two_obstacles.toml) for 10 s
with the jerk limits; its set-points are streamed at 1 kHz (loops/servo.py) and played on the
MuJoCo twin of the iiwa14 (sim/twin.py), one servo tick per step, on one core:
  twin_realtime_factor   simulated seconds per wall second of the twin's steps (target ≥ 5)
  servo_stream_us        one control period's stream, median (ServoStream.period)
  twin_period_us         one control period's ten twin steps, median
  qp_step_us             one qp control period, median: the baseline of the same process
"""

from __future__ import annotations

import statistics
import time

from common import run

from articula.book.study import packaged
from articula.experiments.plan import build_plan
from articula.loops.servo import ServoLimits, ServoStream
from articula.sim.twin import Twin
from articula.validation import load_toml

SECONDS = 10.0
RATE = 1000.0


def measure() -> dict[str, float]:
    path = packaged("ch1", "circle_two_obstacles.toml")
    data = load_toml(path)
    data["planner"].update(method="qp", limits="velocity+acceleration+jerk")
    plan = build_plan(data, path.parent, str(path))
    controller = plan.controller()
    dt = plan.spec.dt
    stream = ServoStream(ServoLimits.of(plan.scene.robot), dt, RATE)
    stream.reset(plan.q0)
    twin = Twin(plan.scene, RATE)
    twin.reset(plan.q0)
    steps, streams, twins = [], [], []
    for k in range(round(SECONDS / dt)):
        start = time.perf_counter_ns()
        q = controller.step(plan.reference(k * dt), q_measured=twin.q)
        planned = time.perf_counter_ns()
        ticks = stream.period(q)
        streamed = time.perf_counter_ns()
        for q_ref, qd_ref, _ in ticks:
            twin.step(q_ref, qd_ref)
        played = time.perf_counter_ns()
        steps.append(planned - start)
        streams.append(streamed - planned)
        twins.append(played - streamed)
    m = {
        "twin_realtime_factor": SECONDS / (sum(twins) / 1e9),
        "servo_stream_us": statistics.median(streams) / 1e3,
        "twin_period_us": statistics.median(twins) / 1e3,
        "qp_step_us": statistics.median(steps) / 1e3,
        "periods": float(len(steps)),
    }
    return m


def table(m: dict[str, float]) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        [
            "twin_realtime_factor (simulated s per wall s)",
            f"{m['twin_realtime_factor']:.1f}",
            "≥ 5",
        ],
        ["servo_stream_us (one period at 1 kHz)", f"{m['servo_stream_us']:.1f}", ""],
        ["twin_period_us (ten twin steps)", f"{m['twin_period_us']:.1f}", ""],
        ["qp_step_us (one qp period, baseline)", f"{m['qp_step_us']:.1f}", ""],
    ]
    title = f"the twin, median over {int(m['periods'])} periods"
    return title, ["measure", "value", "target"], rows


if __name__ == "__main__":
    run(__doc__, measure, table)
