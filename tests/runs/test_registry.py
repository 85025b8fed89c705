"""The registry: experiments found by name through entry points, configs validated and dumped."""

from __future__ import annotations

from pathlib import Path

import pytest

from articula.errors import ConfigError
from articula.runs import registry
from articula.runs.registry import (
    Experiment,
    config_to_dict,
    experiment,
    names,
    parse_config,
    with_absolute_paths,
)

BUILT_IN = ("baornn.plan", "motor.current", "pneunet.pid", "softarm.damping")


def test_every_built_in_experiment_is_installed_under_its_name():
    assert set(BUILT_IN) <= set(names())
    for name in BUILT_IN:
        found = experiment(name)
        assert isinstance(found, Experiment) and found.name == name


def test_an_unknown_experiment_names_the_field_and_lists_the_choices():
    with pytest.raises(ConfigError) as err:
        experiment("motor.voltage")
    assert err.value.field == "experiment"
    for name in BUILT_IN:
        assert name in err.value.problem


def test_a_config_without_experiment_is_refused_naming_its_file():
    with pytest.raises(ConfigError) as err:
        parse_config({"duration": 1.0}, "run.toml")
    assert err.value.field == "run.toml: experiment"


def test_parse_then_dump_fills_every_default_and_keeps_the_name():
    exp, model = parse_config({"experiment": "motor.current", "duration": 0.5, "settle": 0.2})
    full = config_to_dict(exp, model)
    assert full["experiment"] == "motor.current" and full["duration"] == 0.5
    assert "controller" in full and "pwm" in full
    assert config_to_dict(*parse_config(full)) == full  # a complete config is a fixed point


def test_paths_are_made_absolute_by_the_experiment_that_owns_them(tmp_path):
    plan = {"experiment": "baornn.plan", "obstacles": [{"mesh": "rock.stl"}]}
    out = with_absolute_paths(plan, tmp_path)
    assert Path(out["obstacles"][0]["mesh"]) == (tmp_path / "rock.stl").resolve()
    motor = {"experiment": "motor.current", "duration": 1.0}
    assert with_absolute_paths(motor, tmp_path) == motor


def test_a_config_of_no_known_experiment_passes_through_for_validation_to_refuse(tmp_path):
    data = {"experiment": "nope", "mesh": "x.stl"}
    assert with_absolute_paths(data, tmp_path) == data


def test_an_entry_point_that_is_not_its_experiment_is_refused(monkeypatch):
    class Entry:
        name = "motor.current"
        value = "somewhere:else"

        def load(self):
            return object()

    monkeypatch.setattr(registry, "_entry_points", lambda: {"motor.current": Entry()})
    with pytest.raises(ConfigError, match="not the Experiment"):
        experiment("motor.current")
