"""A drive's run folder: the planner's set-points and what the arm measured, as `plan` writes
its own (config.toml, record.json, trace.parquet), with the measured columns qm_1..qm_n, the
servo loop's deadline misses and lateness, and the twin's metrics from the measured joints."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from articula.arms.realtime import scheduling
from articula.arms.servo_loop import ServoLoop
from articula.experiments.plan import PlanSetup
from articula.loops.sampled_clearance import sampled_clearance
from articula.runs import records
from articula.runs.folders import claimed
from articula.runs.registry import Result

if TYPE_CHECKING:
    from articula.experiments.drive import DriveOptions

__all__ = ["DriveRun", "write_drive"]


@dataclass
class DriveRun:
    """One drive as it goes.

    Attributes:
        plan: the plan driven (started where the arm was).
        options: the arm, rate and start tolerance.
        loop: the servo loop (its measurements and lateness).
        offset: how far each joint started from robot.q0, shape (n,) [rad].
        setpoints: the planner's set-point of each period, (n,) [rad] each.
        step_s: the wall time of each period's planner step [s].
    """

    plan: PlanSetup
    options: DriveOptions
    loop: ServoLoop
    offset: np.ndarray
    setpoints: list[np.ndarray] = field(default_factory=list)
    step_s: list[float] = field(default_factory=list)

    def trace(self) -> dict[str, np.ndarray]:
        """One row per period streamed: t [s], q_j (set-points) and qm_j (measured at the
        period's end) [rad], the measured tool x, y, z and its reference x_ref, y_ref, z_ref
        then, and their distance `error` [m].

        Returns:
            Column name -> values.
        """
        robot, dt = self.plan.scene.robot, self.plan.spec.dt
        ticks = self.loop.stream.ticks
        measured = [m.q for m in self.loop.measured]
        periods, n = min(len(self.setpoints), (len(measured) - 1) // ticks), len(measured[0])
        q = np.array(self.setpoints[:periods]).reshape(periods, n)
        qm = np.array([measured[(k + 1) * ticks] for k in range(periods)]).reshape(periods, n)
        t = np.arange(periods) * dt
        tool = np.array([robot.ee_position(row) for row in qm]).reshape(periods, 3)
        ref = np.array([self.plan.reference(tk + dt).position for tk in t]).reshape(periods, 3)
        columns = {"t": t} | {f"q_{j + 1}": q[:, j] for j in range(q.shape[1])}
        columns |= {f"qm_{j + 1}": qm[:, j] for j in range(qm.shape[1])}
        columns |= {a: tool[:, i] for i, a in enumerate("xyz")}
        columns |= {f"{a}_ref": ref[:, i] for i, a in enumerate("xyz")}
        return columns | {"error": np.linalg.norm(tool - ref, axis=1)}

    def metrics(self, trace: dict[str, np.ndarray]) -> dict[str, Any]:
        """The drive's metrics.

        Args:
            trace: the run's trace (DriveRun.trace).

        Returns:
            periods; start_offset (largest joint offset from robot.q0 [rad]);
            plant_rms_error, plant_max_error (the measured tool from its reference once
            settled, planner.settle into the path [m]); the servo loop's servo_releases,
            servo_deadline_misses, servo_deadline_miss_fraction, servo_latency_p50_ms,
            _p99_ms, _max_ms; planner_step_p50_ms, _p99_ms, _max_ms (the planner's wall
            time a period [ms]); measured_max_velocity_ratio and
            measured_max_acceleration_ratio (differences of the measured joints at the
            arm's own timestamps, over the limits); plant_final_speed [rad/s]; the measured
            arm's clearances (plant_min_clearance, ... of loops.sampled_clearance).
        """
        plan, loop = self.plan, self.loop
        settle = plan.reference.duration + (plan.spec.settle or 0.0)
        settled = trace["t"] + plan.spec.dt >= settle
        error = trace["error"][settled]
        metrics: dict[str, Any] = {
            "periods": float(len(trace["t"])),
            "start_offset": float(np.max(np.abs(self.offset))),
            "plant_rms_error": float(np.sqrt(np.mean(error**2))) if error.size else None,
            "plant_max_error": float(np.max(error)) if error.size else None,
        }
        metrics |= loop.pacer.latency().as_metrics("servo")
        if self.step_s:
            p50, p99 = np.percentile(self.step_s, [50, 99])
            metrics |= {"planner_step_p50_ms": 1e3 * p50, "planner_step_p99_ms": 1e3 * p99,
                        "planner_step_max_ms": 1e3 * max(self.step_s)}  # fmt: skip
        t = np.array([m.t for m in loop.measured])
        q = np.array([m.q for m in loop.measured])
        fresh = np.concatenate([[True], np.diff(t) > 0])  # a read within one controller cycle
        t, q = t[fresh], q[fresh]
        robot = plan.scene.robot
        if len(t) > 2:
            v = np.diff(q, axis=0) / np.diff(t)[:, None]
            a = np.diff(v, axis=0) / np.diff(t)[1:, None]
            metrics["measured_max_velocity_ratio"] = float(np.max(np.abs(v) / robot.velocity_limit))
            metrics["measured_max_acceleration_ratio"] = float(
                np.max(np.abs(a) / robot.acceleration_limit)
            )
            metrics["plant_final_speed"] = float(np.max(np.abs(v[-1])))
        every = max(1, loop.stream.ticks // 2)  # clearances at twice the planner's rate
        return metrics | sampled_clearance(plan.scene, q[::every], t[::every] - t[0], "plant")


def write_drive(
    out: Path,
    config: dict[str, Any],
    run: DriveRun,
    outcome: str,
    wall_time: float,
    force: bool,
) -> dict[str, Any]:
    """Write the drive's run folder.

    Args:
        out: the run folder.
        config: the plan config as read (its `experiment` key set).
        run: the drive.
        outcome: "done", or what ended it.
        wall_time: how long it streamed [s].
        force: write into a folder holding files articula did not write.

    Returns:
        The record written.
    """
    trace = run.trace()
    details = {
        "drive": {"arm": run.options.arm, "rate_hz": run.options.rate, "outcome": outcome,
                  "start_tolerance": run.options.tolerance, "scheduling": scheduling(),
                  "client_messages": list(getattr(run.loop.arm, "messages", []))}
    }  # fmt: skip
    result = Result(run.metrics(trace), trace, details=details)
    record = records.build_record(config, result, wall_time)
    with claimed(out, "run", force):
        records.write_run(out, config, record, trace)
    return record
