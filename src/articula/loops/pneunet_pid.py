"""The PneuNet's closed loop: a PID of the family (2.2)-(2.4) against a batch of actuators.

The controller works in the unit of its reference (degrees in chapter 2, as the book's gains
are per degree) and outputs the valve's PWM count; the plant is `plants.pneunet.PneuNetBatch`.
`SimulatedRig` is the tuner's view of it: run one experiment with gains K, return the response.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from articula.control.pid import PID, GainSchedule
from articula.plants.pneunet import PneuNetBatch, PneuNetParams
from articula.tuning.response import Response


@dataclass(frozen=True, eq=False)
class ClosedLoopTrace:
    """Times [s] (n,), reference [°] (n,); measured, true angle [°] and duty, (trials, n).

    The arrays are read-only.

    Attributes:
        t: start time of each PWM period, shape (n,) [s].
        reference: reference angle, shape (n,) [°].
        measured: angle the flex sensor reads, shape (trials, n) [°].
        theta: true bending angle, shape (trials, n) [°].
        duty: valve duty cycle applied, shape (trials, n), in [0, 1].
    """

    t: np.ndarray
    reference: np.ndarray
    measured: np.ndarray
    theta: np.ndarray
    duty: np.ndarray


def run_closed_loop(
    params: PneuNetParams,
    controller: PID,
    reference: np.ndarray,
    seeds: Sequence[int],
    vary: bool = True,
) -> ClosedLoopTrace:
    """Run the controller against one actuator per seed; reference [°] at each PWM period.

    Trial i splits numpy.random.SeedSequence(seeds[i]) into two streams: the first draws its
    sensor noise, the second its actuator variation. So a trial gives the same numbers alone or
    in a batch, and trial i is the same actuator whatever the run's length (or frequency).

    Args:
        params: the actuator's constants.
        controller: the PID, reference and measurement in degrees, output the PWM count
            (its upper output limit is full duty); reset to `len(seeds)` trials first.
        reference: reference angle at each PWM period, shape (n,) [°].
        seeds: one seed per trial.
        vary: scale each trial's actuator by its own draw of PneuNetParams.trial_factors;
            False keeps the nominal actuator for every trial (only the sensor noise differs).

    Returns:
        The trace of every trial, read-only.
    """
    steps = reference.size
    trials = len(seeds)
    streams = [np.random.SeedSequence(s).spawn(2) for s in seeds]
    noise = np.stack([np.random.default_rng(n).standard_normal(steps) for n, _ in streams])
    factors = (
        np.stack([params.trial_factors(np.random.default_rng(a)) for _, a in streams])
        if vary
        else None
    )
    plant = PneuNetBatch(params, trials, factors)
    controller.reset(trials)
    full_scale = controller.output_limits[1]
    t = np.arange(steps) * params.pwm_period
    measured, theta, duty = (np.empty((trials, steps)) for _ in range(3))
    for n in range(steps):
        measured[:, n] = np.degrees(plant.read(noise[:, n]))
        theta[:, n] = np.degrees(plant.theta)
        u = controller(t[n], reference[n], measured[:, n])
        duty[:, n] = np.floor(u) / full_scale  # analogWrite takes an integer count
        plant.advance(duty[:, n])
    reference = np.array(reference, dtype=float)  # the trace keeps its own copy
    for array in (t, reference, measured, theta, duty):
        array.setflags(write=False)
    return ClosedLoopTrace(t, reference, measured, theta, duty)


class SimulatedRig:
    """The tuner's view of the actuator: run one experiment with gains K, return its response.

    Each call is a new experiment with fresh sensor noise (seed, seed + 1, ...) on the same,
    nominal actuator, as in one tuning session on a rig.

    Args:
        params: the actuator's constants.
        reference: reference angle at each PWM period, shape (n,) [°].
        seed: seed of the first experiment's sensor noise.

    Attributes:
        calls: experiments run so far.
    """

    def __init__(self, params: PneuNetParams, reference: np.ndarray, seed: int) -> None:
        self.params = params
        self.reference = np.asarray(reference, dtype=float)
        self.seed = seed
        self.calls = 0

    def __call__(self, gains: np.ndarray) -> Response:
        """One experiment from rest with constant gains [K_p, K_i, K_d].

        Args:
            gains: [K_p, K_i, K_d], shape (3,), from the error [°] to the PWM count.

        Returns:
            The reference [°] and measured angle [°] over time [s].
        """
        schedule = GainSchedule("constant", np.asarray(gains, dtype=float)[None, :])
        pid = PID(schedule, (0.0, 255.0))
        trace = run_closed_loop(
            self.params, pid, self.reference, [self.seed + self.calls], vary=False
        )
        self.calls += 1
        return Response(trace.t, trace.reference, trace.measured[0])
