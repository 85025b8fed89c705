"""What `articula live` recorded, period by period, and its run folder (`--record`), which
`articula view` replays."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from articula.errors import ArticulaError
from articula.experiments.plan import NAME as PLAN
from articula.loops.tracking import PlanResult, trace_columns, tracking_metrics
from articula.runs.records import build_record, write_run
from articula.runs.registry import Result
from articula.scene.scene import Scene
from articula.viewer import drawing
from articula.viewer.run_data import TRACK


@dataclass
class Recording:
    """What happened, period by period: times [s], configurations [rad], end-effector and
    target positions [m], clearance [m], obstacle poses (name -> [x, y, z, qw, qx, qy, qz]).

    Attributes:
        t: each period's planner time [s].
        q: each period's joint positions, shape (n,) each [rad].
        x: each period's end-effector position, shape (3,) each [m].
        x_ref: each period's target position, shape (3,) each [m].
        clearance: each period's smallest clearance [m] (inf without obstacles).
        obstacles: obstacle name -> its pose each period, [x, y, z (m), qw, qx, qy, qz].
        step_ms: each period's planner wall time [ms].
        measured_clearance: each period's smallest clearance of the measured arm [m] (with
            `live --plant`; empty without).
        self_clearance: each period's smallest distance between the links of a checked
            pair [m]; empty when the scene checks none (robot.self_collision off).
    """

    t: list[float] = field(default_factory=list)
    q: list[np.ndarray] = field(default_factory=list)
    x: list[np.ndarray] = field(default_factory=list)
    x_ref: list[np.ndarray] = field(default_factory=list)
    clearance: list[float] = field(default_factory=list)
    obstacles: dict[str, list[np.ndarray]] = field(default_factory=dict)
    step_ms: list[float] = field(default_factory=list)
    measured_clearance: list[float] = field(default_factory=list)
    self_clearance: list[float] = field(default_factory=list)

    def add(
        self,
        t: float,
        q: np.ndarray,
        x: np.ndarray,
        target: np.ndarray,
        clearance: float,
        poses: dict[str, np.ndarray],
        self_clearance: float | None = None,
    ) -> None:
        """Record one period.

        Args:
            t: the period's planner time [s].
            q: the commanded joints, shape (n,) [rad].
            x: the end effector there, shape (3,) [m].
            target: the period's target, shape (3,) [m].
            clearance: the smallest clearance there [m].
            poses: obstacle name -> its pose (4×4, world).
            self_clearance: the smallest distance of a checked link pair there [m]; None:
                the scene checks none.
        """
        self.t.append(t)
        self.q.append(q.copy())
        self.x.append(x)
        self.x_ref.append(np.asarray(target, dtype=float).copy())
        self.clearance.append(clearance)
        for name, T in poses.items():
            wxyz, position = drawing.wxyz_position(T)
            self.obstacles.setdefault(name, []).append(np.r_[position, wxyz])
        if self_clearance is not None:
            self.self_clearance.append(self_clearance)

    def write(
        self,
        folder: Path,
        config: dict[str, Any],
        scene: Scene,
        q0: np.ndarray,
        dt: float,
        iterations: float,
        plant: Any,
        wall_time: float,
    ) -> dict[str, Any]:
        """The recording as a run folder `articula view` replays. A signal that ends the
        session lands anywhere in a period, between one column's row and the next: the period
        it cut short is left out, so every column has the same periods. The record's
        min_self_clearance and self_collisions are those of the checked link pairs, and None,
        as in `plan`'s record, when the scene checks none (robot.self_collision off).

        Args:
            folder: the run folder to write.
            config: the scene file as a plan config, with the panel's last settings.
            scene: the robot and obstacles (their starting poses).
            q0: the start configuration, shape (n,) [rad].
            dt: the control period [s].
            iterations: the planner's iterations per period.
            plant: the measured arm (sim.twin_arm.TwinArm), its columns and metrics added;
                None: none.
            wall_time: the session's wall-clock duration, for the record [s].

        Returns:
            The run's record (record.json).
        """
        if not self._keep_whole_periods(plant, bool(scene.self_pairs)):
            raise ArticulaError("--record: nothing happened yet (no control period ran)")
        x, x_ref = np.array(self.x), np.array(self.x_ref)
        run = PlanResult(
            np.array(self.t),
            np.array(self.q),
            x,
            x_ref,
            np.linalg.norm(x - x_ref, axis=1),
            np.array(self.clearance),
            1e-3 * float(np.sum(self.step_ms[1:])),
            1e-3 * self.step_ms[0],
            q0,
            self_clearance=np.array(self.self_clearance) if scene.self_pairs else None,
        )
        metrics = tracking_metrics(run, scene.robot, 0.0, iterations)
        metrics["overrun_fraction"] = float(np.mean(np.array(self.step_ms) > 1e3 * dt))
        trace = trace_columns(run)
        for name, rows in self.obstacles.items():
            for c, column in zip(TRACK, np.array(rows).T, strict=True):
                trace[f"obstacle_{name}_{c}"] = column
        if plant is not None:
            metrics |= plant.metrics(run, scene, 0.0, np.array(self.measured_clearance))
            trace |= plant.columns()
        config = {**config, "experiment": PLAN}
        record = build_record(config, Result(metrics, {}), wall_time)
        write_run(folder, config, record, trace)
        return record

    def _keep_whole_periods(self, plant: Any, self_checked: bool) -> int:
        """Cut every per-period column (the plant's too; self_clearance when `self_checked`)
        to the periods all of them reached.

        Returns:
            The number of periods kept.
        """
        columns = [self.t, self.q, self.x, self.x_ref, self.clearance, self.step_ms]
        columns += self.obstacles.values()
        if self_checked:
            columns.append(self.self_clearance)
        if plant is not None:
            columns.append(self.measured_clearance)
        periods = min(map(len, columns))
        if plant is not None:
            periods = min(periods, plant.periods)
            plant.truncate(periods)
        for rows in columns:
            del rows[periods:]
        return periods
