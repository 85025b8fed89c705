"""The pacer: releases on schedule, lateness and misses counted by hand, late schedules kept
or restarted (an injected clock: no wall clock)."""

from __future__ import annotations

import pytest

from articula.arms.pacing import Pacer
from articula.errors import ConfigError


class FakeClock:
    """A clock that moves only when slept on or pushed."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += seconds


def test_releases_come_a_period_apart_and_none_is_late():
    clock = FakeClock()
    pacer = Pacer(0.002, clock=clock, sleep=clock.sleep)
    times = []
    for _ in range(5):
        pacer.wait()
        times.append(clock.now)
    assert times == pytest.approx([0.0, 0.002, 0.004, 0.006, 0.008])
    assert pacer.latency().misses == 0 and pacer.latency().max_s == 0.0


def test_a_release_late_by_a_period_is_a_miss_and_its_lateness_is_recorded():
    clock = FakeClock()
    pacer = Pacer(0.002, clock=clock, sleep=clock.sleep)
    pacer.wait()
    clock.now += 0.0055  # the loop's body ran over: due at 0.002, released at 0.0055
    assert pacer.wait() == pytest.approx(0.0035)
    pacer.wait()  # due at 0.004, still late: caught up at once
    latency = pacer.latency()
    assert latency.misses == 1 and latency.releases == 3
    assert latency.max_s == pytest.approx(0.0035)
    assert latency.miss_fraction == pytest.approx(1 / 3)


def test_without_catch_up_a_late_release_restarts_the_schedule():
    clock = FakeClock()
    pacer = Pacer(0.002, catch_up=False, clock=clock, sleep=clock.sleep)
    pacer.wait()
    clock.now += 0.0055
    pacer.wait()
    pacer.wait()
    assert clock.now == pytest.approx(0.0075)  # a period after the late release


def test_a_period_that_is_not_positive_is_refused():
    with pytest.raises(ConfigError, match="period"):
        Pacer(0.0)
