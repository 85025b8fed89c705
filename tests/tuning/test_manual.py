"""tuning/manual.py: the scripted manual procedure and Ziegler–Nichols, on made-up responses
and on the simulated PneuNet."""

import numpy as np
import pytest

from articula.errors import ConfigError, InfeasibleError
from articula.loops.pneunet_pid import SimulatedRig
from articula.plants.pneunet import PneuNetParams
from articula.tuning.manual import Ladder, manual_tuning, ultimate_gain, ziegler_nichols
from articula.tuning.response import Response


def test_ziegler_nichols_table():
    assert ziegler_nichols(10.0, 2.0, "PID") == pytest.approx([6.0, 6.0, 1.5])
    assert ziegler_nichols(10.0, 2.0, "PI") == pytest.approx([4.5, 2.7, 0.0])
    assert ziegler_nichols(10.0, 2.0, "P") == pytest.approx([5.0, 0.0, 0.0])


def test_ziegler_nichols_rejects_an_unknown_rule_and_a_bad_gain():
    with pytest.raises(ConfigError) as exc:
        ziegler_nichols(10.0, 2.0, "PD")
    assert exc.value.field == "rule"
    with pytest.raises(ConfigError):
        ziegler_nichols(-1.0, 2.0)


def test_ladder_values_and_bad_ladder():
    assert Ladder(start=1.0, factor=2.0, stop=8.0).values() == [1.0, 2.0, 4.0, 8.0]
    with pytest.raises(ConfigError):
        Ladder(start=1.0, factor=0.5, stop=8.0)


def _fake(shape):
    """An Experiment whose 10 s step response to 90° is shape(t, gains), with call count."""
    t = np.arange(0, 10, 0.01)
    calls = []

    def experiment(gains):
        calls.append(np.array(gains))
        return Response(t, np.full_like(t, 90.0), shape(t, gains))

    return experiment, calls


def test_manual_procedure_lets_k_d_lower_the_overshoot():
    # Overshoot 90·e^-1·(2s − 1), s = 1 − 20·K_d: 33° at K_d = 0, then 19.9°, 6.6° and 0° at
    # K_d = 0.01, 0.02, 0.04; at 0.08 nothing is left to lower, so K_d = 0.04 is kept.
    def shape(t, k):
        s = max(0.0, 1 - 20 * k[2])
        return 90.0 * (1 - np.exp(-2 * t) * (s * np.cos(2 * np.pi * t) + 1 - s))

    experiment, calls = _fake(shape)
    result = manual_tuning(experiment)
    assert result.gains.tolist() == [0.25, 0.0, 0.04]  # converging at the first K_p
    assert [t.gains[2] for t in result.trials] == [0.0, 0.01, 0.02, 0.04, 0.08]
    assert len(calls) == len(result.trials) and result.within_tolerance
    assert (
        "K_i = 0" in result.trials[0].decision and "keep K_d = 0.04" in result.trials[-1].decision
    )


def test_manual_procedure_tries_k_d_even_without_overshoot_and_never_reruns():
    # First order, no overshoot, a 5° offset that no K_i removes: the K_p ladder runs to its
    # top, every K_i rung fails (recorded, not hidden), one K_d > 0 is tried and rejected.
    experiment, calls = _fake(lambda t, k: 85.0 * (1 - np.exp(-3 * t)))
    result = manual_tuning(experiment)
    gains = [tuple(t.gains) for t in result.trials]
    assert len(set(gains)) == len(gains) == len(calls)  # no experiment run twice
    assert not result.within_tolerance
    assert "top of the ladder with the error above tolerance" in result.trials[-2].decision
    assert result.trials[-1].gains[2] == 0.01 and result.gains[2] == 0.0
    assert (
        result.gains[0]
        == max(t.gains[0] for t in result.trials)
        == Ladder(start=0.25, factor=1.5, stop=40.0).values()[-1]
    )


def test_manual_procedure_refuses_a_first_k_p_that_already_swings():
    experiment, calls = _fake(lambda t, k: 90.0 * (1 - np.cos(2 * np.pi * t)))
    with pytest.raises(InfeasibleError, match=r"kp\.start"):
        manual_tuning(experiment)
    assert len(calls) == 1


def test_ultimate_gain_without_sustained_swings_is_infeasible():
    experiment, _ = _fake(lambda t, k: 90.0 * (1 - np.exp(-3 * t)))
    with pytest.raises(InfeasibleError, match="raise the ladder's stop"):
        ultimate_gain(experiment, Ladder(start=0.5, factor=2.0, stop=4.0), band=2.0)


def _rig(level: float, seconds: float, seed: int = 0) -> SimulatedRig:
    return SimulatedRig(PneuNetParams(), np.full(round(seconds * 30), level), seed)


def test_manual_procedure_follows_its_own_rules():
    result = manual_tuning(_rig(75.0, 10.0))
    kp, ki, kd = result.gains
    p_only = [t for t in result.trials if t.gains[1] == 0 and t.gains[2] == 0]
    # K_p: every smaller rung showed no oscillation; the chosen one converges (or the next grew).
    chosen = next(t for t in p_only if t.gains[0] == kp)
    assert chosen.features.converging or any(t.gains[0] > kp for t in p_only)
    assert all(not t.features.oscillates for t in p_only if t.gains[0] < kp)
    # K_i: the final response has its steady-state error within tolerance (1°).
    final = [t for t in result.trials if np.array_equal(t.gains, result.gains)][-1]
    assert final.features.steady_state_error <= 1.0 and ki > 0
    assert kd >= 0 and all(t.decision for t in result.trials)
    assert any(t.gains[2] > 0 for t in result.trials)  # K_d > 0 always tried


def test_tuning_records_are_read_only():
    result = manual_tuning(_rig(45.0, 4.0))
    for array in (result.gains, result.trials[0].gains, result.trials[0].response.measured):
        with pytest.raises(ValueError):
            array[0] = 1.0


def test_ultimate_gain_finds_a_sustained_oscillation():
    ku, tu, trials = ultimate_gain(
        _rig(90.0, 10.0), Ladder(start=0.5, factor=1.5, stop=100.0), band=2.0
    )
    assert trials[-1].decision == "sustained" and trials[-1].gains[0] == ku
    assert 0.1 < tu < 2.0
