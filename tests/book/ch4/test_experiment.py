"""The `motor.current` experiment: config validation, seeding of batches, metrics from sums."""

from __future__ import annotations

import math

import numpy as np
import pytest

from articula.control.moving_average import moving_average
from articula.errors import ConfigError
from articula.experiments.motor import (
    CurrentControlConfig,
    run_current_control,
    simulate_batch,
    time_axis,
)
from articula.validation import parse_model
from tests.oracles import rise_time, sinusoid_fit

TABLE_4_2_DICT = {"R": 8.35, "K": 0.4485, "b": 0.002, "J": 0.1}


def config(**fields) -> CurrentControlConfig:
    return parse_model(CurrentControlConfig, fields)


def noisy_config(**extra) -> CurrentControlConfig:
    """The book's unfiltered-or-filtered rig with every non-ideality on, kept short."""
    return config(duration=0.6, settle=0.3, **extra)


# ----- validation ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "fields",
    [
        {"duration": 2.0, "settle": 2.0},
        {"duration": 1.0, "settle": 3.0},
        {"dt": math.nan},
        {"duration": math.nan},
        {"settle": math.nan},
        {"duration": math.inf},
        {"reference": {"current": math.nan}},
        {"reference": {"frequency": math.nan}},
        {"controller": {"kp": math.nan}},
        {"pwm": {"v_max": math.nan}},
        {"motor": {**TABLE_4_2_DICT, "R": math.nan}},
        {"sensor": {"noise_pp": math.nan}},
    ],
    ids=lambda f: repr(f)[:40],
)
def test_bad_configs_raise_config_error(fields: dict):
    with pytest.raises(ConfigError):
        parse_model(CurrentControlConfig, fields)


@pytest.mark.parametrize(
    "reference", [{}, {"amplitude": 0.1, "frequency": 5.0}], ids=["step", "sinusoid"]
)
@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")
def test_config_with_empty_steady_window_is_rejected(reference: dict):
    fields = {"duration": 2.0, "settle": 1.9995, "reference": reference}
    with pytest.raises(ConfigError):
        parse_model(CurrentControlConfig, fields)


@pytest.mark.parametrize(
    ("fields", "field"),
    [
        ({"duration": 2.0, "settle": 2.0}, "settle"),
        ({"duration": 2.0, "settle": 1.9995}, "settle"),
        ({"duration": 2.0, "settle": 1.0, "reference": {"current": 2.0}}, "reference"),
        ({"duration": 1.2, "settle": 1.0, "reference": {"amplitude": 0.1, "frequency": 5.0}},
         "duration"),
    ],
)  # fmt: skip
def test_a_check_across_fields_names_its_field_in_the_file(fields: dict, field: str):
    with pytest.raises(ConfigError, match=rf"^m\.toml: {field}: "):
        parse_model(CurrentControlConfig, fields, "m.toml")


def test_zero_step_has_no_rise_time():
    cfg = config(duration=0.5, settle=0.3, reference={"current": 0.0, "speed": 5.0})
    _, m = simulate_batch(cfg, 1)
    assert np.isnan(m["rise_time"][0])
    assert np.isnan(m["rise_time_feedback"][0])


def test_valid_config_round_trips():
    cfg = parse_model(CurrentControlConfig, {"duration": 2.0, "settle": 1.98})
    assert cfg.steps == 2000


# ----- reproducibility ----------------------------------------------------------------------------


@pytest.mark.parametrize("trials", [2, 5, 16])
def test_trial_zero_of_a_batch_is_the_single_run_bitwise(trials: int):
    cfg = noisy_config(seed=7, controller={"filter_order": 4})
    single = run_current_control(cfg)
    channels, metrics = simulate_batch(cfg, trials)
    assert channels is not None
    for name, trace in channels.items():
        assert trace.shape == (trials, cfg.steps)
        np.testing.assert_array_equal(trace[0], single.trace[name], err_msg=name)
    for name, value in metrics.items():
        np.testing.assert_array_equal(value[0], single.metrics[name], err_msg=name)
    # The other trials see other noise.
    assert not np.array_equal(channels["i_meas"][1], channels["i_meas"][0])


def test_a_trial_does_not_depend_on_the_batch_size():
    cfg = noisy_config(seed=8)
    small, m_small = simulate_batch(cfg, 2)
    large, m_large = simulate_batch(cfg, 9)
    for name in small:
        np.testing.assert_array_equal(small[name], large[name][:2], err_msg=name)
    for name in m_small:
        np.testing.assert_array_equal(m_small[name], m_large[name][:2], err_msg=name)


def test_same_seed_same_numbers_other_seed_other_numbers():
    a = run_current_control(noisy_config(seed=3))
    b = run_current_control(noisy_config(seed=3))
    c = run_current_control(noisy_config(seed=4))
    for name in a.trace:
        np.testing.assert_array_equal(a.trace[name], b.trace[name], err_msg=name)
    assert a.metrics.keys() == b.metrics.keys()
    for name in a.metrics:
        np.testing.assert_array_equal(a.metrics[name], b.metrics[name], err_msg=name)
    assert not np.array_equal(a.trace["i_meas"], c.trace["i_meas"])
    assert not np.array_equal(a.trace["i"], c.trace["i"])
    assert a.metrics["noise_rms"] != c.metrics["noise_rms"]


def test_unrecorded_batch_has_the_same_metrics():
    cfg = noisy_config(seed=1, controller={"filter_order": 8})
    channels, recorded = simulate_batch(cfg, 3, record=True)
    none, streamed = simulate_batch(cfg, 3, record=False)
    assert channels is not None
    assert none is None
    for name in recorded:
        np.testing.assert_array_equal(recorded[name], streamed[name], err_msg=name)


# ----- metrics from the loop's running sums -------------------------------------------------------


def test_streaming_metrics_equal_metrics_computed_from_the_trace():
    k = 4
    cfg = config(seed=11, duration=1.0, settle=0.4, controller={"filter_order": k})
    ch, m = simulate_batch(cfg, 3)
    t = time_axis(cfg)
    steady = t >= cfg.settle
    i, i_ref = ch["i"][:, steady], ch["i_ref"][:, steady]
    np.testing.assert_allclose(m["steady_state_error"], (i - i_ref).mean(axis=1), atol=1e-12)
    np.testing.assert_allclose(
        m["current_rms_error"], np.sqrt(((i - i_ref) ** 2).mean(axis=1)), rtol=1e-9
    )
    noise = ch["i_fb"][:, steady] - moving_average(ch["i"], k)[:, steady]
    np.testing.assert_allclose(m["noise_rms"], np.sqrt((noise**2).mean(axis=1)), rtol=1e-9)
    np.testing.assert_allclose(m["speed_mean"], ch["omega"][:, steady].mean(axis=1), rtol=1e-12)
    saturated = np.abs(ch["duty1"]) >= 255
    np.testing.assert_allclose(m["saturation_fraction"], saturated.mean(axis=1), rtol=1e-12)
    np.testing.assert_allclose(m["rise_time"], rise_time(t, ch["i"], 0.0, 1.0), atol=1e-12)
    np.testing.assert_allclose(
        m["rise_time_feedback"], rise_time(t, ch["i_fb"], 0.0, 1.0), atol=1e-12
    )
    assert np.all(np.isnan(m["amplitude_ratio"]))


def test_streaming_sinusoid_fit_equals_least_squares_on_the_trace():
    w = 25.0
    cfg = config(seed=12, duration=1.5, settle=0.7, reference={"amplitude": 0.1, "frequency": w})
    ch, m = simulate_batch(cfg, 2)
    t = time_axis(cfg)
    steady = t >= cfg.settle
    amplitude, phase = sinusoid_fit(t[steady], ch["i"][:, steady], w)
    np.testing.assert_allclose(m["amplitude_ratio"], amplitude / 0.1, rtol=1e-8)
    np.testing.assert_allclose(m["phase_lag"], -phase, atol=1e-8)
    assert np.all(np.isnan(m["rise_time"]))


@pytest.mark.parametrize("current", [-1e308, -1e12, -2.0])
def test_a_current_the_driver_cannot_reach_either_way_is_refused(current):
    with pytest.raises(ConfigError) as err:
        parse_model(CurrentControlConfig, {"reference": {"current": current}})
    assert "reference" in str(err.value)
