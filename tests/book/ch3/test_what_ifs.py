"""Chapter 3's single simulations: the model's constants, sensitivity, mechanism, stiffening."""

from __future__ import annotations

import pytest

from articula.book.ch3 import what_ifs
from articula.book.ch3.analysis import body_overshoot
from articula.book.ch3.calibration import undamped
from articula.plants.six_chamber import SixChamberParams


def test_outcome_by_default_is_the_undamped_calibration_run():
    m = undamped(SixChamberParams())
    o = what_ifs.outcome()
    assert (o.peak_deg, o.settling_s, o.bend_deg) == (
        m["peak_true_deg"], m["settling_true_s"], m["deactuation_angle_deg"],
    )  # fmt: skip


def test_actuator_model_fills_to_half_supply_before_ninety_percent():
    m = what_ifs.actuator_model()
    assert 0 < m.fill_half_s < m.fill_90_s
    assert m.gas_stiffness_half > m.gas_stiffness_atm > 0
    assert 0 < m.damping_ratio < 1


def test_sensitivity_changes_one_constant_per_row():
    cases = what_ifs.sensitivity()
    assert len(cases) == len(what_ifs.ORIFICES) + len(what_ifs.TRANSITIONS)
    assert cases[0].label == "orifice 0.5 mm" and cases[-1].label == "flow_transition 5000 Pa"


@pytest.mark.parametrize(
    ("delta", "peak", "chosen"),
    [
        ([0.0, 0.1, 0.2, 0.3, 0.4], [19.0, 18.6, 18.4, 18.5, 10.0], 0.2),  # 0.4 is past 0.35
        ([0.0, 0.1, 0.2], [19.0, None, 18.9], 0.2),  # a missing peak counts as the worst
        ([0.0, 0.5, 0.6], [19.0, 18.0, 17.0], 0.6),  # no small δ: the largest
    ],
)
def test_mechanism_delta_is_the_best_small_delta(delta, peak, chosen):
    assert what_ifs.mechanism_delta(delta, peak) == chosen


def test_release_vents_chamber_zero_before_the_body_comes_to_rest():
    r = what_ifs.release(0.0)
    assert r.vented_s > 0 and r.rest_s > 0
    assert 0 < r.overshoot < 1
    assert r.p0_mean > 0


def test_air_in_the_vented_chambers_damps_more_than_the_body_alone():
    m = what_ifs.actuator_model()
    free = what_ifs.release(0.0)
    assert what_ifs.vented_overshoot(free.beta0, free.direction) < body_overshoot(m.damping_ratio)


def test_stiffening_lowers_the_undamped_peak():
    rows = what_ifs.stiffening()
    assert [r.stiffening for r in rows] == list(what_ifs.STIFFENING)
    peaks = [r.outcomes[0].peak_deg for r in rows]
    assert peaks == sorted(peaks, reverse=True)
