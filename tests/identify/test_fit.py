"""fit_constants against closed forms: a decay whose constants it must find within their
standard errors, whose standard errors match the spread over noise draws, and a constant with
no effect, which it must name as undetermined rather than guess."""

from __future__ import annotations

import numpy as np

from articula.identify.fit import fit_constants, nrmse

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
