"""validation.py: StrictModel names a bad field "ClassName.field", parse_model names it after the
file, the shared field types refuse what they should, and fields_as renames the field of an error
from the library's argument name to the config path."""

from __future__ import annotations

import math

import pytest
from pydantic import model_validator

from articula.errors import ConfigError, InfeasibleError
from articula.validation import (
    Finite,
    NonNegative,
    Positive,
    StrictModel,
    field_error,
    fields_as,
    parse_model,
)


class Gains(StrictModel):
    """A small parameter model: one field of each shared type and a check across fields."""

    offset: Finite = 0.0
    kd: NonNegative = 0.0
    kp: Positive = 1.0
    limit: Positive = 10.0

    @model_validator(mode="after")
    def _kp_within_limit(self) -> Gains:
        if self.kp > self.limit:
            raise field_error("kp", f"must be at most limit = {self.limit}")
        return self


class Loop(StrictModel):
    gains: Gains = Gains()


# ----- StrictModel ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"offset": math.nan}, "offset"),
        ({"offset": math.inf}, "offset"),
        ({"kd": -0.1}, "kd"),
        ({"kp": 0.0}, "kp"),
        ({"kp": -1.0}, "kp"),
        ({"kp": "1"}, "kp"),  # strict: no string to number conversion
    ],
)
def test_a_bad_value_is_named_class_dot_field(kwargs, field):
    with pytest.raises(ConfigError) as exc:
        Gains(**kwargs)
    assert exc.value.field == f"Gains.{field}"
    assert exc.value.loc == (field,)
    assert "got" in exc.value.problem  # the value it refused


def test_the_shared_types_accept_their_bounds():
    gains = Gains(offset=-3.0, kd=0.0, kp=1e-9)
    assert (gains.offset, gains.kd, gains.kp) == (-3.0, 0.0, 1e-9)


def test_an_unknown_key_is_named_and_refused():
    with pytest.raises(ConfigError, match="unknown key") as exc:
        Gains(ki=1.0)
    assert exc.value.field == "Gains.ki"


def test_a_check_across_fields_names_its_field():
    with pytest.raises(ConfigError, match=r"limit = 2\.0") as exc:
        Gains(kp=3.0, limit=2.0)
    assert exc.value.field == "Gains.kp"


def test_a_nested_model_is_named_through_the_outer_class():
    with pytest.raises(ConfigError) as exc:
        Loop(gains={"kp": -1.0})
    assert exc.value.field == "Loop.gains.kp"


def test_a_model_takes_keyword_arguments_only_and_is_frozen():
    with pytest.raises(TypeError):
        Gains(0.0)  # type: ignore[misc]
    gains = Gains()
    with pytest.raises(ValueError):
        gains.kp = 2.0  # type: ignore[misc]


def test_config_errors_are_value_errors():
    with pytest.raises(ValueError):
        Gains(kp=0.0)


# ----- parse_model ------------------------------------------------------------------------------


def test_parse_model_names_the_field_after_the_file():
    with pytest.raises(ConfigError) as exc:
        parse_model(Loop, {"gains": {"kd": -1.0}}, "loop.toml")
    assert exc.value.field == "loop.toml: gains.kd"
    assert exc.value.loc == ("gains", "kd")


def test_parse_model_without_a_file_names_the_path_alone():
    with pytest.raises(ConfigError) as exc:
        parse_model(Loop, {"gains": {"kp": 3.0, "limit": 2.0}})
    assert exc.value.field == "gains.kp"


# ----- fields_as --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "error",
    [ConfigError("q0", "needs 7 joint values"), InfeasibleError("needs 7 joint values", "q0")],
    ids=["config", "infeasible"],
)
def test_fields_as_renames_the_field_of_an_error(error):
    with pytest.raises(type(error)) as exc, fields_as({"q0": "robot.q0"}):
        raise error
    assert exc.value.field == "robot.q0"
    assert exc.value.problem == "needs 7 joint values"
    assert str(exc.value) == "robot.q0: needs 7 joint values"


@pytest.mark.parametrize(
    "error",
    [ConfigError("dt", "must be > 0"), InfeasibleError("out of reach", "trajectory"),
     InfeasibleError("out of reach")],
    ids=["config", "infeasible", "infeasible_without_field"],
)  # fmt: skip
def test_fields_as_leaves_errors_of_other_fields_as_they_are(error):
    with pytest.raises(type(error)) as exc, fields_as({"q0": "robot.q0"}):
        raise error
    assert exc.value is error


def test_fields_as_lets_other_exceptions_and_results_through():
    with pytest.raises(KeyError), fields_as({"q0": "robot.q0"}):
        raise KeyError("q0")
    with fields_as({"q0": "robot.q0"}):
        value = 1 + 1
    assert value == 2


def test_a_union_fields_error_names_the_key_not_pydantics_member_tag():
    from articula.scene.config import ObstacleSpec

    with pytest.raises(ConfigError) as err:
        parse_model(ObstacleSpec, {"mesh": "m.stl", "scale": 1e308}, "scene.toml")
    assert err.value.field == "scene.toml: scale"
