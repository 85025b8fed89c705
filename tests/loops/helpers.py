"""Helpers of the loop tests: motor.current configs built the way users build them."""

from __future__ import annotations

from articula.experiments.motor import CurrentControlConfig
from articula.validation import parse_model

IDEAL = {"sensor": {"ideal": True}, "encoder": {"ideal": True}, "pwm": {"bits": 0}}


def config(**fields) -> CurrentControlConfig:
    """A motor.current config from keyword fields, validated as a config file would be."""
    return parse_model(CurrentControlConfig, fields)
