"""loops/pneunet_pid.py: the PneuNet's PID loop over a batch of trials: a trial is the same alone
or in a batch and whatever the run length, varies only through its seed, and the book's gains track
slow sinusoids but not fast ones (Sect. 2.4.2)."""

import numpy as np
import pytest

from articula.control.pid import PID, GainSchedule
from articula.loops.pneunet_pid import SimulatedRig, run_closed_loop
from articula.plants.pneunet import PneuNetParams
from articula.tuning.response import Response, step_features, tuning_cost

P = PneuNetParams()


def _pid(kp, ki, kd, trials=1):
    return PID(GainSchedule("constant", np.array([[kp, ki, kd]])), (0.0, 255.0), trials=trials)


def test_batch_trials_equal_single_trials_seed_by_seed():
    reference = 45.0 - 45.0 * np.cos(2 * np.pi * 0.2 * np.arange(150) / 30.0)
    seeds = [7, 8, 9, 10]
    batch = run_closed_loop(P, _pid(1.0, 2.0, 0.05, 4), reference, seeds)
    for i, seed in enumerate(seeds):
        single = run_closed_loop(P, _pid(1.0, 2.0, 0.05), reference, [seed])
        np.testing.assert_array_equal(batch.measured[i], single.measured[0])
        np.testing.assert_array_equal(batch.theta[i], single.theta[0])
        np.testing.assert_array_equal(batch.duty[i], single.duty[0])
    assert not np.array_equal(batch.measured[0], batch.measured[1])


def test_a_trial_is_the_same_actuator_whatever_the_run_length():
    # The actuator variation has its own stream, so the first samples of a short run equal
    # those of a long run of the same seed (the old order, noise then variation, failed this).
    reference = 45.0 - 45.0 * np.cos(2 * np.pi * 0.5 * np.arange(300) / 30.0)
    short = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference[:60], [4])
    long = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [4])
    np.testing.assert_array_equal(short.theta[0], long.theta[0, :60])
    np.testing.assert_array_equal(short.measured[0], long.measured[0, :60])
    nominal = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference[:60], [4], vary=False)
    np.testing.assert_array_equal(short.measured[0, :1], nominal.measured[0, :1])  # same noise
    assert not np.array_equal(short.theta[0], nominal.theta[0])


def test_trials_vary_only_through_their_seed():
    reference = np.full(90, 45.0)
    a = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [3])
    b = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [3])
    nominal = run_closed_loop(P, _pid(1.0, 2.0, 0.0), reference, [3], vary=False)
    np.testing.assert_array_equal(a.theta, b.theta)
    assert not np.array_equal(a.theta, nominal.theta)


def _amplitude_ratio(frequency: float) -> float:
    """Closed-loop |θ/θ_r| at `frequency` [Hz] with the book's automatic gains at 45°."""
    steps = round(max(3 / frequency, 10.0) * 30)
    t = np.arange(steps) / 30.0
    reference = 45.0 - 30.0 * np.cos(2 * np.pi * frequency * t)
    trace = run_closed_loop(P, _pid(1.48, 3.77, 0.0), reference, [0], vary=False)
    keep = t >= t[-1] / 3
    basis = np.stack([np.ones(keep.sum()), np.sin(2 * np.pi * frequency * t[keep]),
                      np.cos(2 * np.pi * frequency * t[keep])], axis=1)  # fmt: skip
    coef = np.linalg.lstsq(basis, trace.theta[0, keep], rcond=None)[0]
    return float(np.hypot(coef[1], coef[2]) / 30.0)


def test_calibration_tracks_half_a_hertz_but_not_five():
    # Sect. 2.4.2.2: tracks sinusoids up to about 0.5 Hz; cannot follow 5 Hz.
    assert _amplitude_ratio(0.05) > 0.9
    assert _amplitude_ratio(0.5) > 0.5
    assert _amplitude_ratio(5.0) < 0.1


@pytest.mark.parametrize("seed", [1, 2])
def test_calibration_a_large_derivative_term_makes_it_oscillate(seed):
    # Sect. 2.4.2.1: K_d ≠ 0 gives oscillations. At a 45° step, K_d = 0.3 makes the true angle
    # swing beyond the 2° band without dying out; K_d = 0 gives no swing at all.
    reference = np.full(240, 45.0)
    results = {}
    for kd in (0.0, 0.3):
        tr = run_closed_loop(P, _pid(1.0, 2.0, kd), reference, [seed], vary=False)
        true = step_features(Response(tr.t, tr.reference, tr.theta[0]), 2.0)
        cost = float(tuning_cost(tr.t, tr.reference, tr.measured[0]))
        results[kd] = (true, cost)
    swinging, calm = results[0.3][0], results[0.0][0]
    assert swinging.sustained() and swinging.peak_sizes.size >= 10
    assert swinging.peak_sizes[-4:].min() > 5.0  # still > 5° at the end of the 8 s
    assert calm.peak_sizes.size == 0
    assert results[0.3][1] > 1.5 * results[0.0][1]  # M (2.5)


def _rig(level: float, seconds: float, seed: int = 0) -> SimulatedRig:
    return SimulatedRig(PneuNetParams(), np.full(round(seconds * 30), level), seed)


def test_rig_runs_one_fresh_experiment_per_call():
    rig = _rig(45.0, 2.0)
    a, b = rig(np.array([1.0, 2.0, 0.0])), rig(np.array([1.0, 2.0, 0.0]))
    assert rig.calls == 2 and not np.array_equal(a.measured, b.measured)
    again = _rig(45.0, 2.0)(np.array([1.0, 2.0, 0.0]))
    np.testing.assert_array_equal(a.measured, again.measured)
