"""Chapter 2's tuners on a PneuNet rig over serial (`articula rig tune`): the book's
coordinate descent (Algorithm 1), scripted manual tuning and Ziegler-Nichols, each probe one
experiment on the rig.

With `--model PLANT.toml` (a fitted PneuNet, `articula identify`'s plant.toml) the descent runs
on the model in simulation, then is confirmed on the rig: a descent on the rig from the model's
gains, with steps of a tenth of them, for CONFIRM_SWEEPS sweep(s), every experiment on the rig
counted (tune_on_model).

Beside tuning.json it writes tuned.toml, a pneunet.pid config of the tuned gains on the
tuning's steps (with the fitted plant as its [plant] when tuned on a model), which `articula
rig run PORT tuned.toml` runs on the rig and `articula run tuned.toml` in simulation.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from articula.book.ch2.study import ZN_LADDER, ZN_SEED_OFFSET
from articula.book.ch2.tuning import TuningConfig, auto_run, auto_seed, manual_seed
from articula.book.study import packaged
from articula.errors import ConfigError
from articula.experiments.pneunet import PneuNetPidConfig
from articula.experiments.pneunet_on_rig import plant_config
from articula.plants.pneunet import PneuNetParams
from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetRig
from articula.rigs.programs import steps
from articula.rigs.protocol import RigKind
from articula.runs.folders import TUNED, TUNING, check_out, claimed
from articula.runs.records import atomic_write
from articula.tuning.coordinate_descent import coordinate_descent
from articula.tuning.manual import (
    GainExperiment,
    ManualSettings,
    manual_tuning,
    ultimate_gain,
    ziegler_nichols,
)
from articula.tuning.response import Response, tuning_cost
from articula.validation import load_toml, parse_model

TUNERS = ("descent", "manual", "ziegler-nichols")
CONFIRM_SWEEPS = 1  # sweeps of the descent on the rig (each at most 6 experiments, + 1)
CONFIRM_STEP = 0.1  # its probing steps, as a fraction of the model's gains


def rig_experiment(
    link: Link,
    levels: tuple[float, ...],
    hold: float,
    seed: int,
    on_experiment: Callable[[], None] | None = None,
) -> GainExperiment:
    """One experiment on the rig per call: steps through `levels` [°], each held `hold` [s],
    with the gains K = (K_p, K_i, K_d) it is called with; on_experiment() before each.

    Args:
        link: the line to a PneuNet rig.
        levels: the reference's levels [°].
        hold: how long each is held [s].
        seed: the noise seed of an emulated rig.
        on_experiment: called before each experiment; None: nothing.

    Returns:
        The experiment: gains -> the rig's response.
    """
    on_rig = PneuNetRig(link, steps(levels, hold), len(levels) * hold, seed)

    def experiment(k: np.ndarray) -> Response:
        if on_experiment is not None:
            on_experiment()
        return on_rig(k)

    return experiment


def tune_on_rig(
    tuning: TuningConfig,
    link: Link,
    method: str,
    levels: tuple[float, ...],
    index: int = 0,
    on_experiment: Callable[[], None] | None = None,
) -> dict[str, Any]:
    """Chapter 2's tuners, unchanged, with the rig behind `link` as their experiment: the
    coordinate descent (Algorithm 1) on steps through `levels`, the scripted manual procedure
    or Ziegler-Nichols' ultimate gain on a step to levels[0] [°]; the noise seeds are the
    in-process runs' (an emulated rig then gives their numbers). Returns the result as JSON."""

    def rig(program_levels: tuple[float, ...], hold: float, seed: int) -> GainExperiment:
        return rig_experiment(link, program_levels, hold, seed, on_experiment)

    m, level = tuning.manual, levels[0]
    if method == "descent":
        run = auto_run(
            tuning, levels, index, rig(levels, tuning.auto.hold, auto_seed(tuning, index))
        ).result
        return {
            "method": method,
            "levels_deg": list(levels),
            "hold_s": tuning.auto.hold,
            "gains": run.k.tolist(),
            "cost": run.cost,
            "experiments": run.evaluations,
            "sweeps": len(run.history) - 1,
        }
    if method == "manual":
        experiment = rig((level,), m.hold, manual_seed(tuning, level))
        found = manual_tuning(experiment, ManualSettings(band=m.band, tolerance=m.tolerance))
        return {
            "method": method,
            "levels_deg": [level],
            "hold_s": m.hold,
            "gains": found.gains.tolist(),
            "experiments": len(found.trials),
            "within_tolerance": found.within_tolerance,
        }
    if method != "ziegler-nichols":
        raise ConfigError("--method", f"unknown tuner {method!r}; choose one of {TUNERS}")
    ku, tu, trials = ultimate_gain(
        rig((level,), m.hold, m.seed + ZN_SEED_OFFSET), ZN_LADDER, m.band
    )
    return {
        "method": method,
        "levels_deg": [level],
        "hold_s": m.hold,
        "ku": ku,
        "tu_s": tu,
        "gains": ziegler_nichols(ku, tu, "PID").tolist(),
        "gains_pi": ziegler_nichols(ku, tu, "PI").tolist(),
        "experiments": len(trials),
    }


def tune_on_model(
    tuning: TuningConfig,
    plant: PneuNetParams,
    link: Link,
    levels: tuple[float, ...],
    index: int = 0,
    on_experiment: Callable[[], None] | None = None,
) -> dict[str, Any]:
    """Tune on the model, then confirm on the rig behind `link`.

    Args:
        tuning: the chapter-2 tuning config (its descent settings; its plant is replaced).
        plant: the fitted PneuNet.
        link: the line to the PneuNet rig.
        levels: the reference's levels [°].
        index: which run of the config's seeds (the start K and dK, the noise seeds).
        on_experiment: called before each experiment on the rig.

    Returns:
        The result as JSON: gains and cost (confirmed on the rig), experiments (on the rig),
        model_gains, model_cost and model_experiments (in simulation), confirm_sweeps.
    """
    model = auto_run(tuning.model_copy(update={"plant": plant}), levels, index).result
    a = tuning.auto
    experiment = rig_experiment(link, levels, a.hold, auto_seed(tuning, index), on_experiment)

    def cost(k: np.ndarray) -> float:
        r = experiment(k)
        return float(tuning_cost(r.t, r.reference, r.measured))  # M(K), Eq. (2.5)

    step = CONFIRM_STEP * np.abs(model.k) + 1e-6
    confirmed = coordinate_descent(cost, model.k, step, a.k_stop, CONFIRM_SWEEPS,
                                   lower=np.zeros(3), upper=np.array(a.upper))  # fmt: skip
    return {
        "method": "descent",
        "model": True,
        "levels_deg": list(levels),
        "hold_s": a.hold,
        "gains": confirmed.k.tolist(),
        "cost": confirmed.cost,
        "experiments": confirmed.evaluations,
        "confirm_sweeps": CONFIRM_SWEEPS,
        "model_gains": model.k.tolist(),
        "model_cost": model.cost,
        "model_experiments": model.evaluations,
    }


def parse_levels(levels: str) -> tuple[float, ...]:
    """Reference levels [°] from a comma-separated list (ConfigError naming --levels)."""
    try:
        return tuple(float(v) for v in levels.split(","))
    except ValueError:
        raise ConfigError(
            "--levels", f"comma-separated angles in degrees (got {levels!r})"
        ) from None


def tune_into(
    out_dir: Path,
    port: str,
    method: str,
    config: Path | None,
    levels: tuple[float, ...],
    index: int,
    force: bool,
    on_experiment: Callable[[], None] | None = None,
    model: Path | None = None,
) -> dict[str, Any]:
    """Tune the PneuNet rig on `port` and write the result to `out_dir`/tuning.json.

    Args:
        out_dir: The run folder (refused as `articula run` refuses one, unless `force`).
        port: The rig's serial port.
        method: One of TUNERS.
        config: A chapter-2 tuning config; None for the book's quick one.
        levels: Reference levels [°] (manual and Ziegler-Nichols: a step to the first).
        index: Which run of the config's seeds.
        force: Overwrite a run folder that holds other files.
        on_experiment: Called before each experiment on the rig.
        model: A fitted plant (`articula identify pneunet`'s plant.toml) to tune on in
            simulation first, then confirm on the rig (tune_on_model); descent
            only. None: every experiment on the rig.

    Returns:
        The result, as written to tuning.json, with the link's statistics under "link".
    """
    if method not in TUNERS:
        raise ConfigError(
            "--method", f"unknown tuner {method!r}; choose one of {', '.join(TUNERS)}"
        )
    data = load_toml(config or packaged("ch2", "tuning_quick.toml"))
    tuning = parse_model(TuningConfig, data, str(config or "tuning_quick.toml"))
    plant = None
    if model is not None:
        if method != "descent":
            raise ConfigError("--model", f"tunes with the descent only (got --method {method})")
        plant = plant_config(model)
    check_out(out_dir, "run", force)
    with Link(port, RigKind.PNEUNET) as link, claimed(out_dir, "run", force):
        if plant is None:
            result = tune_on_rig(tuning, link, method, levels, index, on_experiment)
        else:
            result = tune_on_model(tuning, plant, link, levels, index, on_experiment)
        result["link"] = dataclasses.asdict(link.stats)
        result["tuned"] = TUNED
        atomic_write(out_dir / TUNED, tuned_config(result, plant).encode())
        atomic_write(out_dir / TUNING, json.dumps(result, indent=2).encode())
    return result


def tuned_config(result: dict[str, Any], plant: PneuNetParams | None) -> str:
    """The tuned gains as a pneunet.pid config, on the tuning's own steps: what `rig run` and
    `run` take without an edit.

    Args:
        result: a tuning's result (its method, levels_deg, hold_s and gains).
        plant: the fitted PneuNet it was tuned on, as the config's [plant]; None: none
            written (`run` then simulates the chapter's PneuNet).

    Returns:
        The config as TOML text, checked as `articula run` reads it.
    """
    levels = [float(v) for v in result["levels_deg"]]
    data: dict[str, Any] = {
        "experiment": "pneunet.pid",
        "seed": 0,
        "trials": 1,
        "duration": len(levels) * float(result["hold_s"]),
        "reference": {"kind": "steps", "levels_deg": levels},
        "controller": {"name": f"{result['method']}-tuned", "schedule": "constant",
                       "gains": [[float(k) for k in result["gains"]]]},
    }  # fmt: skip
    if plant is not None:
        data["plant"] = plant.model_dump()
    parse_model(PneuNetPidConfig, {k: v for k, v in data.items() if k != "experiment"}, TUNED)
    head = f"# {result['method']} tuning's gains on the rig (articula rig tune)"
    where = "the fitted plant it was tuned on" if plant else "none: the chapter's PneuNet"
    return f"{head}; [plant]: {where}.\n" + tomli_w.dumps(data)
