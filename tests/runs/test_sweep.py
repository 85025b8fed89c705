"""Sweep files: expansion of base, grid and runs into validated configs."""

from __future__ import annotations

import copy
import itertools
import tomllib

import pytest

from articula.errors import ConfigError
from articula.runs import records, sweep
from articula.runs.registry import config_to_dict, parse_config

BASE = {"experiment": "motor.current", "duration": 0.5, "settle": 0.2}


def test_expand_sweep_count_order_and_contents():
    spec = {
        "base": {**BASE, "reference": {"current": 0.5}},
        "grid": {"controller.filter_order": [1, 2, 3], "seed": [0, 1]},
        "runs": [{"reference": {"amplitude": 0.1, "frequency": 25.0}}, {"rig": "single"}],
    }
    configs = sweep.expand_sweep(spec)
    assert len(configs) == 3 * 2 * 2
    got = [
        (c["controller"]["filter_order"], c["seed"], c["rig"], c["reference"]["frequency"])
        for c in configs
    ]
    runs = [("dual", 25.0), ("single", 0.0)]
    want = [(k, s, *r) for k, s, r in itertools.product([1, 2, 3], [0, 1], runs)]
    assert got == want  # Cartesian product of the grid, each point with every run, in order
    for c in configs:
        assert c["reference"]["current"] == 0.5  # base survives the deep merge with runs
        assert c["duration"] == 0.5 and c["settle"] == 0.2
        assert c["dt"] == 1e-3  # defaults are filled in
        exp, model = parse_config(c)
        assert config_to_dict(exp, model) == c  # already the full, validated config
    amplitudes = {c["rig"]: c["reference"]["amplitude"] for c in configs}
    assert amplitudes == {"dual": 0.1, "single": 0.0}
    assert len({records.config_hash(c) for c in configs}) == len(configs)


def test_expand_sweep_without_grid_or_runs():
    [alone] = sweep.expand_sweep({"base": BASE})
    exp, model = parse_config(BASE)
    assert alone == config_to_dict(exp, model)
    only_runs = sweep.expand_sweep({"base": BASE, "runs": [{"seed": 1}, {"seed": 2}, {}]})
    assert [c["seed"] for c in only_runs] == [1, 2, 0]
    only_grid = sweep.expand_sweep({"base": BASE, "grid": {"pwm.bits": [0, 8, 12]}})
    assert [c["pwm"]["bits"] for c in only_grid] == [0, 8, 12]
    # The experiment may come from the runs instead of the base.
    no_base = sweep.expand_sweep({"runs": [{**BASE, "seed": 3}]})
    assert no_base[0]["seed"] == 3


def test_expand_sweep_of_packaged_bandwidth_sweep():
    from importlib import resources

    path = resources.files("articula.book.ch4") / "configs" / "bandwidth_quick.toml"
    spec = tomllib.loads(path.read_text())
    configs = sweep.expand_sweep(spec)
    assert len(configs) == 5 * 1 * 10
    assert {c["controller"]["filter_order"] for c in configs} == {1, 4, 16, 64, 256}
    assert all(c["reference"]["amplitude"] == 0.1 for c in configs)


@pytest.mark.parametrize(
    ("spec", "field"),
    [
        ({"base": BASE, "grids": {"seed": [0]}}, "grids"),
        ({"base": BASE, "grid": {"seed": 0}}, "grid.seed"),
        ({"base": BASE, "grid": {"seed": []}}, "grid.seed"),
        ({"base": BASE, "grid": {"controller.kd": [1.0]}}, "controller.kd"),
        ({"base": BASE, "grid": {"controler.kp": [1.0]}}, "controler"),
        ({"base": BASE, "grid": {"seed": [0, -1]}}, "seed"),
        ({"base": BASE, "grid": {"controller.filter_order": [1, 0]}}, "controller.filter_order"),
        ({"base": BASE, "grid": {"duration": [1.0, float("nan")]}}, "duration"),
        ({"base": BASE, "grid": {"rig": ["dual", "quad"]}}, "rig"),
        ({"base": {**BASE, "seed": 0}, "grid": {"seed.x": [1]}}, "grid.seed.x"),
        ({"base": BASE, "runs": [{"settle": 9.0}]}, "settle"),
        ({"base": {"duration": 1.0}, "grid": {"seed": [0]}}, "experiment"),
    ],
    ids=[
        "unknown_sweep_key",
        "grid_value_not_list",
        "grid_value_empty",
        "unknown_grid_key",
        "misspelt_table",
        "bad_grid_value",
        "filter_order_zero",
        "nan_grid_value",
        "bad_literal",
        "dotted_through_scalar",
        "invalid_run",
        "missing_experiment",
    ],
)
def test_expand_sweep_rejects_bad_grid(spec, field):
    with pytest.raises(ConfigError) as exc:
        sweep.expand_sweep(spec)
    assert field in exc.value.field
    assert isinstance(exc.value, ValueError)


@pytest.mark.parametrize(
    "spec",
    [
        {"base": BASE, "grid": {"seed": [0, 0]}},
        {"base": BASE, "grid": {"controller.kp": [10, 10.0]}},
        {"base": BASE, "runs": [{}, {"rig": "dual"}]},  # the default rig is dual
        {"base": BASE, "runs": [{"seed": 1}, {"seed": 2}], "grid": {"seed": [0]}},
    ],
    ids=["repeated_value", "same_after_validation", "same_after_defaults", "grid_overrides_runs"],
)
def test_expand_sweep_rejects_duplicate_points(spec):
    with pytest.raises(ConfigError) as exc:
        sweep.expand_sweep(spec)
    assert exc.value.field == "grid"
    assert "same config" in exc.value.problem


def test_expand_sweep_does_not_mutate_its_input():
    spec = {
        "base": BASE,
        "runs": [{"reference": {"amplitude": 0.1}}],
        "grid": {"reference.frequency": [30.0, 40.0]},
    }
    before = copy.deepcopy(spec)
    configs = sweep.expand_sweep(spec)
    assert [c["reference"]["frequency"] for c in configs] == [30.0, 40.0]
    assert spec == before


def test_a_grid_key_indexes_a_list_of_the_base():
    plan = {
        "experiment": "baornn.plan",
        "robot": {"builtin": "iiwa14"},
        "obstacles": [{"sphere": 0.05, "position": [0.4, 0.3, 0.6]}],
        "trajectory": {"type": "waypoints", "points": [[0, 0.6, 0.5], [0, 0.6, 0.6]],
                       "times": [0.0, 1.0]},
    }  # fmt: skip
    configs = sweep.expand_sweep(
        {"base": plan, "grid": {"obstacles.0.position.2": [0.6, 0.7], "obstacles.0.sphere": [0.1]}}
    )
    assert [c["obstacles"][0]["position"] for c in configs] == [[0.4, 0.3, 0.6], [0.4, 0.3, 0.7]]
    assert plan["obstacles"][0]["position"] == [0.4, 0.3, 0.6]  # the base is untouched
    with pytest.raises(ConfigError, match="index"):
        sweep.expand_sweep({"base": plan, "grid": {"obstacles.3.sphere": [0.1]}})


def test_an_empty_runs_list_is_refused():
    with pytest.raises(ConfigError) as err:
        sweep.expand_sweep({"base": BASE, "runs": []})
    assert err.value.field == "runs"


def test_a_sweep_over_the_run_limit_is_refused_before_any_config_is_built():
    grid = {f"k{i}": list(range(10)) for i in range(10)}  # 10**10 points, never expanded
    with pytest.raises(ConfigError) as err:
        sweep.expand_sweep({"base": BASE, "grid": grid}, max_runs=100)
    assert err.value.field == "grid" and "--max-runs" in err.value.problem


def test_an_error_names_the_sweep_file_and_the_point():
    spec = {"base": BASE, "grid": {"seed": [0], "pwm.bits": [8, 99]}}
    with pytest.raises(ConfigError) as err:
        sweep.expand_sweep(spec, where="s.toml")
    assert err.value.field == "s.toml, seed = 0, pwm.bits = 99: pwm.bits"
