"""A wall-clock pacer: release a loop every period, measure how late each release was.

A release is late by the time between its deadline (start + k · period) and the moment the
pacer returns; a deadline is missed when a release is late by a whole period or more, that
is when the next release is already due.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from articula.errors import ConfigError

__all__ = ["Latency", "Pacer"]


@dataclass(frozen=True)
class Latency:
    """How late a paced loop's releases were.

    Attributes:
        releases: releases so far.
        misses: releases late by a period or more.
        p50_s: the median lateness [s].
        p99_s: the 99th percentile of the lateness [s].
        max_s: the largest lateness [s].
    """

    releases: int
    misses: int
    p50_s: float
    p99_s: float
    max_s: float

    @property
    def miss_fraction(self) -> float:
        """Missed deadlines over releases (0 before any release)."""
        return self.misses / self.releases if self.releases else 0.0

    def as_metrics(self, prefix: str) -> dict[str, float]:
        """The lateness as run metrics.

        Args:
            prefix: the metrics' name prefix ("servo", "planner").

        Returns:
            {prefix}_releases, _deadline_misses, _deadline_miss_fraction, and
            _latency_p50_ms, _latency_p99_ms, _latency_max_ms [ms].
        """
        return {
            f"{prefix}_releases": float(self.releases),
            f"{prefix}_deadline_misses": float(self.misses),
            f"{prefix}_deadline_miss_fraction": self.miss_fraction,
            f"{prefix}_latency_p50_ms": 1e3 * self.p50_s,
            f"{prefix}_latency_p99_ms": 1e3 * self.p99_s,
            f"{prefix}_latency_max_ms": 1e3 * self.max_s,
        }


@dataclass
class Pacer:
    """Releases a loop every `period` seconds of the wall clock.

    Args:
        period: the loop's period [s].
        catch_up: after a late release, keep the schedule (True: the next releases come
            sooner until it is met again) or restart it from now (False: a late loop never
            runs twice in a row without a pause).
        clock: the clock [s] (injected for tests).
        sleep: sleeps a number of seconds (injected for tests).

    Attributes:
        lateness: how late each release was [s].
    """

    period: float
    catch_up: bool = True
    clock: Callable[[], float] = time.perf_counter
    sleep: Callable[[float], None] = time.sleep
    lateness: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.period) and self.period > 0):
            raise ConfigError("period", f"must be finite and > 0 s (got {self.period})")
        self._next: float | None = None

    def wait(self) -> float:
        """Sleep until the next release (the first comes at once).

        Returns:
            How late this release is [s] (≥ 0).
        """
        now = self.clock()
        if self._next is None:
            self._next = now
        pause = self._next - now
        if pause > 0:
            self.sleep(pause)
            now = self.clock()
        late = max(0.0, now - self._next)
        self.lateness.append(late)
        if late >= self.period and not self.catch_up:
            self._next = now
        self._next += self.period
        return late

    def latency(self) -> Latency:
        """How late the releases so far were.

        Returns:
            Their count, misses and lateness percentiles.
        """
        late = np.asarray(self.lateness, dtype=float)
        if not late.size:
            return Latency(0, 0, 0.0, 0.0, 0.0)
        misses = int(np.count_nonzero(late >= self.period))
        p50, p99 = np.percentile(late, [50, 99])
        return Latency(late.size, misses, float(p50), float(p99), float(late.max()))
