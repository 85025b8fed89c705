"""fit_constants against closed forms: a decay whose constants it must find within their
standard errors, whose standard errors match the spread over noise draws, and a constant with
no effect, which it must name as undetermined rather than guess."""

from __future__ import annotations

import numpy as np
import pytest

from articula.identify.fit import fit_constants, nrmse
from articula.plants.pneunet import PneuNetParams

T = np.linspace(0.0, 2.0, 400)
TRUE = {"a": 2.0, "tau": 0.3}


def _decay(values: dict[str, float]) -> np.ndarray:
    """a·exp(−t/τ) (the constant c, if given, has no effect)."""
    return values["a"] * np.exp(-T / values["tau"])


def test_a_decay_is_found_and_its_standard_errors_match_the_spread_over_noise_draws():
    sigma, fits = 0.02, []
    rng = np.random.default_rng(0)
    for _ in range(60):
        y = _decay(TRUE) + sigma * rng.standard_normal(T.size)
        fit = fit_constants(lambda v, y=y: (_decay(v) - y) / sigma, {"a": 1.0, "tau": 1.0},
                            ["a", "tau"])  # fmt: skip
        fits.append(fit)
    for name, value in TRUE.items():
        found = np.array([f.values[name] for f in fits])
        errors = np.array([f.standard_errors[name] for f in fits])
        assert abs(found.mean() - value) < 3 * errors.mean() / np.sqrt(len(fits))
        assert 0.7 < found.std() / errors.mean() < 1.3  # the stated error is the spread
    assert abs(fits[0].residual_sigma - 1.0) < 0.1  # residuals weighted by their noise


def test_a_constant_the_data_do_not_touch_is_named_not_guessed():
    y = _decay(TRUE)
    fit = fit_constants(lambda v: _decay(v) - y + 1e-3 * np.sin(T * 50), TRUE | {"c": 5.0},
                        ["a", "tau", "c"])  # fmt: skip
    assert fit.unidentifiable == ("c",)
    assert set(fit.values) == {"a", "tau"} and "c" not in fit.standard_errors


def test_nrmse_is_zero_for_the_signal_and_one_for_its_mean():
    y = np.sin(T * 7)
    assert nrmse(y, y) == 0.0
    assert abs(nrmse(y, np.full_like(y, y.mean())) - 1.0) < 1e-12


@pytest.mark.parametrize("omega", [80.0, pytest.param(150.0, marks=pytest.mark.slow)])
def test_a_pneunet_bending_faster_than_the_sampling_resolves_is_declared_unidentifiable(omega):
    # Four step parts of the excitation's counts, 5 s each at the rig's 30 Hz, with the flex
    # sensor's noise: the mode at 80-150 rad/s has under 4 samples a cycle.
    from articula.identify.pneunet import PneuNetRecording, identify_pneunet, simulate

    rng, dt = np.random.default_rng(3), 1 / 30
    hidden = {"natural_frequency": omega, "damping_ratio": 0.15}
    recordings = []
    for count in (220, 120, 180, 60):
        pwm = np.r_[np.full(150, count), np.zeros(150)]
        angle = simulate(hidden, PneuNetRecording(dt, pwm, np.zeros(pwm.size)))
        recordings.append(PneuNetRecording(dt, pwm, angle + rng.normal(0, 0.35, pwm.size)))
    found = identify_pneunet(recordings)
    assert {"natural_frequency", "damping_ratio"} <= set(found.fit.unidentifiable)
    assert "natural_frequency" not in found.fit.values
    assert found.bounds["natural_frequency"].startswith("≥ 47.1 rad/s")
    assert found.fit.values["chamber_tau"] == pytest.approx(PneuNetParams().chamber_tau, rel=0.1)


def test_the_book_pneunet_bending_keeps_its_mode_identified():
    from articula.identify.pneunet import PneuNetRecording, identify_pneunet, simulate

    rng, dt = np.random.default_rng(3), 1 / 30
    recordings = []
    for count in (220, 120, 180, 60):
        pwm = np.r_[np.full(150, count), np.zeros(150)]
        angle = simulate({}, PneuNetRecording(dt, pwm, np.zeros(pwm.size)))
        recordings.append(PneuNetRecording(dt, pwm, angle + rng.normal(0, 0.35, pwm.size)))
    found = identify_pneunet(recordings)
    assert not found.bounds
    omega = PneuNetParams().natural_frequency
    assert found.fit.values["natural_frequency"] == pytest.approx(omega, rel=0.05)
