"""Chapter 4's study: the model numbers, the book's runs and the bandwidth sweep, with figures."""

from __future__ import annotations

import math
import shutil
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import control as ct
import numpy as np

from articula.book.ch4 import book_values as book
from articula.book.ch4.analysis import BandwidthRow, bandwidth_rows
from articula.book.study import Study, packaged, read_metrics, read_trace
from articula.experiments.motor import (
    CurrentControlConfig,
    CurrentControllerConfig,
    loop_settings,
)
from articula.loops.motor_current_linear import bandwidth, closed_loop, is_stable
from articula.plants.dc_motor import (
    TABLE_4_1,
    TABLE_4_2,
    MotorParams,
    critical_speed,
    current_at_speed,
    state_space,
    steady_state,
)
from articula.plants.motor_rig import discretize, rig_matrices
from articula.runs.registry import parse_config
from articula.runs.sweep import expand_sweep
from articula.validation import load_toml

RUNS = "runs"  # sweep folder of the book's runs
SWEEP = "bandwidth_sweep"  # sweep folder of the bandwidth study; its file is copied beside it
SIMULATED_SECONDS = 120.0  # [s] from rest: long after the slow mechanical pole has settled
SIMULATED_SAMPLES = 200_001
FIG4_3_POINTS = 200


@dataclass(frozen=True)
class ModelNumbers:
    """The closed-form numbers of Sects. 4.2-4.3 and one simulation that checks them.

    Attributes:
        omega_per_volt: ω_ss/V for Table 4.1, Eq. (4.8) [rad/(s·V)].
        current_per_volt: i_ss/V for Table 4.1, Eq. (4.8) [A/V].
        omega_at_supply: ω_ss at 12 V, Eq. (4.9) [rad/s].
        current_at_supply: i_ss at 12 V, Eq. (4.9) [A].
        simulated_omega: ω after 120 s at 12 V from rest, simulated [rad/s].
        simulated_current: i after the same [A].
        current_with_load: i_ss at 12 V with τ_ex = −0.3 N·m, Eq. (4.10) [A].
        denominator: bR + K² of Eq. (4.8) for Table 4.1 [N²·m²/A²].
        omega_c: critical speed for Table 4.2 at 12 V and 1 A [rad/s].
        stall_current: Table 4.2's current at standstill and 12 V, Eq. (4.11) [A].
        no_load_speed: Table 4.2's speed where the current falls to 0 at 12 V [rad/s].
    """

    omega_per_volt: float
    current_per_volt: float
    omega_at_supply: float
    current_at_supply: float
    simulated_omega: float
    simulated_current: float
    current_with_load: float
    denominator: float
    omega_c: float
    stall_current: float
    no_load_speed: float


@dataclass(frozen=True)
class Ch4Results:
    """Everything chapter 4's report shows.

    Attributes:
        model: the numbers of Sects. 4.2-4.3.
        runs: metrics of each figure run (fig4_5 ... fig4_9; NaN where the run has none, such
            as a sinusoid's rise time), with its filter order under "k".
        gains: kp [V/A], ki [V/(A·s)], R [Ω] and dt [s] of the figure runs' loop (Fig. 4.6's).
        bandwidth: the bandwidth sweep per filter order, ascending.
        sweep_runs: number of runs in the bandwidth sweep.
    """

    model: ModelNumbers
    runs: dict[str, dict[str, float]]
    gains: dict[str, float]
    bandwidth: list[BandwidthRow]
    sweep_runs: int


def run_study(study: Study) -> Ch4Results:
    """Compute the model numbers, run the book's runs and the bandwidth sweep into study.out
    (resuming finished runs), and draw Figs. 4.3, 4.5-4.9 and the bandwidth figure."""
    study.out.mkdir(parents=True, exist_ok=True)
    sweep_file = packaged("ch4", f"bandwidth_{study.size}.toml")
    sweep = expand_sweep(load_toml(sweep_file))
    shutil.copyfile(sweep_file, study.out / f"{SWEEP}.toml")
    figures = {name: load_toml(packaged("ch4", f"{name}.toml")) for name in book.FIGURES}
    total = len(figures) + len(sweep)
    study.sweep(list(figures.values()), RUNS, total=total)
    table = study.sweep(sweep, SWEEP, done=len(figures), total=total).to_pydict()
    runs = {}
    for name, raw in figures.items():
        _, config = parse_config(raw)
        metrics = read_metrics(study.out / RUNS, raw)
        runs[name] = {
            **{k: math.nan if v is None else v for k, v in metrics.items()},
            "k": config.controller.filter_order,
        }
    orders = sorted(set(table["controller.filter_order"]))
    rows = bandwidth_rows(table, {k: linear_bandwidth(k) for k in orders})
    _, fig4_6 = parse_config(figures["fig4_6"])
    gains = {
        "kp": fig4_6.controller.kp,
        "ki": fig4_6.controller.ki,
        "R": fig4_6.params.R,
        "dt": fig4_6.dt,
    }
    model = model_numbers()
    _figures(study.out, figures, model, rows)
    return Ch4Results(model, runs, gains, rows, len(sweep))


def model_numbers() -> ModelNumbers:
    """The numbers of Sects. 4.2-4.3 for Tables 4.1 and 4.2."""
    p, q, V = TABLE_4_1, TABLE_4_2, book.SUPPLY
    w1, i1 = steady_state(p, 1.0)
    w12, i12 = steady_state(p, V)
    ws, is_ = simulated_steady_state(p, V, SIMULATED_SECONDS)
    _, i_load = steady_state(p, V, torque=book.LOAD_TORQUE)
    return ModelNumbers(
        omega_per_volt=w1,
        current_per_volt=i1,
        omega_at_supply=w12,
        current_at_supply=i12,
        simulated_omega=ws,
        simulated_current=is_,
        current_with_load=i_load,
        denominator=p.b * p.R + p.K**2,  # Eq. (4.8)
        omega_c=critical_speed(q, V, book.CRITICAL_CURRENT),
        stall_current=current_at_speed(q, V, 0.0),  # Eq. (4.11) at ω = 0
        no_load_speed=V / q.K,  # Eq. (4.11) at i = 0
    )


def simulated_steady_state(p: MotorParams, voltage: float, seconds: float) -> tuple[float, float]:
    """(ω [rad/s], i [A]) after `seconds` [s] of constant `voltage` [V] from rest, simulated by
    python-control on Eq. (4.6)."""
    A, B = state_space(p)
    sys = ct.ss(A, B[:, 1:], np.eye(2), np.zeros((2, 1)))
    t = np.linspace(0.0, seconds, SIMULATED_SAMPLES)
    y = ct.forced_response(sys, t, np.full((1, t.size), voltage)).outputs
    return float(y[0, -1]), float(y[1, -1])


def linear_bandwidth(filter_order: int) -> tuple[bool, float]:
    """(stable, −3 dB bandwidth [rad/s]) of the default loop linearised with this filter order
    (ideal sensor and driver); the bandwidth is NaN when the loop is unstable."""
    cfg = CurrentControlConfig(controller=CurrentControllerConfig(filter_order=filter_order))
    sys = closed_loop(*discretize(*rig_matrices(cfg.params, True), cfg.dt), loop_settings(cfg))
    stable = is_stable(sys)
    return stable, bandwidth(sys, cfg.dt) if stable else float("nan")


def _figures(
    out: Path,
    figures: Mapping[str, dict[str, Any]],
    model: ModelNumbers,
    rows: list[BandwidthRow],
) -> None:
    """Fig. 4.3, the response of each book run and the bandwidth trade-off."""
    from articula.book.ch4.figures import bandwidth_tradeoff, current_speed_line, response

    q, V = TABLE_4_2, book.SUPPLY
    omega = np.linspace(0.0, model.no_load_speed, FIG4_3_POINTS)
    current = np.array([current_at_speed(q, V, w) for w in omega])
    current_speed_line(
        omega,
        current,
        model.omega_c,
        book.CRITICAL_CURRENT,
        "Current against speed at 12 V (Table 4.2), Eq. (4.11)",
        out / "fig4_3.png",
    )
    for name, raw in figures.items():
        _, config = parse_config(raw)
        trace = read_trace(out / RUNS, raw)
        response(trace, book.FIGURES[name], out / f"{name}.png", config.pwm.bits)
    bandwidth_tradeoff(
        [r.k for r in rows],
        [r.measured for r in rows],
        [r.predicted for r in rows],
        [r.noise for r in rows],
        {r.k: (r.frequencies, r.ratios) for r in rows},
        out / "bandwidth.png",
    )
