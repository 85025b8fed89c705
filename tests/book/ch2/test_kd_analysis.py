"""book/ch2/kd_analysis.py: the K_d probe's verdicts and the tuners' K_d, on made-up inputs."""

import numpy as np
import pytest

from articula.book.ch2.kd_analysis import (
    KdVerdict,
    descent_kd,
    kd_summary,
    kd_verdict,
    kd_zero_status,
    tried_kd,
)
from articula.book.ch2.tuning import KdProbe, TuningRun
from articula.errors import ConfigError
from articula.tuning.coordinate_descent import DescentResult, DescentStep
from articula.tuning.manual import ManualResult, Trial
from articula.tuning.response import Response, step_features

NOISE = np.array([0.3, -0.2, 0.1, -0.4, 0.2, 0.0, -0.1, 0.3])
BASE = 20.0 + NOISE


def _probe(*rows, sustained=None, swings=None):
    """A probe of K_d = 0, 0.1, 0.2, ... with these rows of M (2.5)."""
    cost = np.array(rows, dtype=float)
    swings = np.zeros_like(cost) if swings is None else np.array(swings)
    lasting = np.zeros(cost.shape, dtype=bool) if sustained is None else np.array(sustained)
    return KdProbe(tuple(0.1 * j for j in range(len(rows))), cost, swings, lasting)


def test_a_k_d_that_lowers_m_beyond_noise_is_better():
    v = kd_verdict(_probe(BASE, BASE - 1.0 + 0.01 * NOISE))
    assert v == KdVerdict(better=(0.1,), worse=(), lowest=0.1)


def test_a_k_d_that_raises_m_beyond_noise_is_worse():
    v = kd_verdict(_probe(BASE, BASE + 1.0 + 0.01 * NOISE))
    assert v == KdVerdict(better=(), worse=(0.1,), lowest=0.0)


def test_a_difference_within_the_noise_is_neither():
    v = kd_verdict(_probe(BASE, 20.0 - 0.02 + NOISE[::-1]))
    assert v == KdVerdict(better=(), worse=(), lowest=0.1)


def test_a_k_d_that_swings_without_dying_out_is_worse_at_the_same_m():
    v = kd_verdict(_probe(BASE, BASE, sustained=[[False] * 8, [True] * 8]))
    assert v.worse == (0.1,)


def test_swinging_does_not_count_when_k_d_zero_swings_too():
    v = kd_verdict(_probe(BASE, BASE, sustained=[[True] * 8, [True] * 8]))
    assert v.worse == ()


def test_a_probe_must_start_at_k_d_zero():
    with pytest.raises(ConfigError) as exc:
        kd_verdict(KdProbe((0.1, 0.2), np.ones((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))))
    assert exc.value.field == "kd"


def test_summary_has_mean_m_median_swings_and_sustained_counts():
    s = kd_summary(_probe(BASE, BASE + 1.0, swings=[[0] * 8, [1, 2, 3, 4, 5, 6, 7, 8]],
                          sustained=[[False] * 8, [True] * 3 + [False] * 5]))  # fmt: skip
    assert s.mean_cost == pytest.approx([BASE.mean(), BASE.mean() + 1.0])
    assert s.median_swings.tolist() == [0.0, 4.5] and s.sustained.tolist() == [0, 3]
    assert s.verdict.worse == (0.1,)


WORSE, NEITHER = KdVerdict((), (0.2,), 0.0), KdVerdict((), (), 0.1)
BETTER = KdVerdict((0.05,), (0.2,), 0.05)


def test_k_d_zero_is_reproduced_when_every_set_is_clearly_against_k_d():
    assert kd_zero_status({"a": WORSE, "b": WORSE}) == "reproduced"


def test_k_d_zero_is_inconclusive_when_some_set_does_not_care():
    assert kd_zero_status({"a": WORSE, "b": NEITHER}) == "inconclusive"


def test_k_d_zero_is_not_reproduced_when_some_set_prefers_k_d():
    assert kd_zero_status({"a": WORSE, "b": BETTER}) == "not reproduced"


def test_k_d_zero_needs_a_probed_set():
    with pytest.raises(ConfigError):
        kd_zero_status({})


def _descent(*kd_and_step):
    """A descent run whose history has these (K_d, dK_d) pairs."""
    history = [DescentStep(i, np.array([1.0, 1.0, kd]), np.array([0.1, 0.1, dk]), 1.0, i)
               for i, (kd, dk) in enumerate(kd_and_step)]  # fmt: skip
    return TuningRun((45.0,), DescentResult(history[-1].k, 1.0, len(history), history))


def test_descent_kd_reports_start_end_and_steps():
    d = descent_kd(_descent((0.1, 0.05), (0.15, 0.05), (0.15, 0.01)))
    assert (d.start, d.final, d.moved, d.step_start, d.step_final) == (0.1, 0.15, True, 0.05, 0.01)


def test_descent_kd_sees_a_k_d_that_never_moved():
    assert not descent_kd(_descent((0.1, 0.05), (0.1, 0.02))).moved


def test_tried_kd_lists_the_positive_k_d_values_once_in_order():
    t = np.linspace(0, 1, 10)
    r = Response(t, np.ones_like(t), np.ones_like(t))
    f = step_features(r, 0.1)
    trials = [Trial(np.array([1.0, 1.0, kd]), r, f, "made up") for kd in (0.0, 0.02, 0.01, 0.02)]
    assert tried_kd(ManualResult(np.array([1.0, 1.0, 0.0]), trials)) == (0.01, 0.02)
