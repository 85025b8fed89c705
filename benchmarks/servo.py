"""Cost of the servo stream per control period, beside the planner's step it follows.

    python benchmarks/servo.py [--json]

qp tracks the book's two-obstacle circle (book/ch1/configs/circle_two_obstacles.toml) for 10 s
with the jerk limits; its set-points are then streamed at 1 kHz (loops/servo.py), one
ServoStream.period call per set-point, as a live loop would, median over the periods:
  servo_stream_us      one period's stream (10 ticks of position, velocity, acceleration)
  qp_step_us           one qp control period (OnlineController.step), the baseline
  stream_over_step     servo_stream_us / qp_step_us
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from common import run

from articula.book.study import packaged
from articula.experiments.plan import build_plan
from articula.loops.servo import ServoLimits, ServoStream
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
    steps, periods = [], []
    for k in range(round(SECONDS / dt)):
        target = plan.reference(k * dt)
        start = time.perf_counter_ns()
        q = controller.step(target)
        middle = time.perf_counter_ns()
        ticks = stream.period(q)
        periods.append(time.perf_counter_ns() - middle)
        steps.append(middle - start)
        assert np.all(np.isfinite(ticks))
    m = {
        "servo_stream_us": statistics.median(periods) / 1e3,
        "qp_step_us": statistics.median(steps) / 1e3,
        "periods": float(len(periods)),
    }
    m["stream_over_step"] = m["servo_stream_us"] / m["qp_step_us"]
    return m


def table(m: dict[str, float]) -> tuple[str, list[str], list[list[str]]]:
    """The measures as (title, columns, rows) for a person."""
    rows = [
        ["servo_stream_us (one period at 1 kHz)", f"{m['servo_stream_us']:.1f}"],
        ["qp_step_us (one qp period, baseline)", f"{m['qp_step_us']:.1f}"],
        ["stream_over_step", f"{m['stream_over_step']:.2f}×"],
    ]
    return f"servo stream, median over {int(m['periods'])} periods", ["measure", "value"], rows


if __name__ == "__main__":
    run(__doc__, measure, table)
