"""Moving-average filter of order k on a sampled signal, Eq. (4.17) taken as a mean."""

from __future__ import annotations

import numpy as np
from numba import njit

from articula.errors import ConfigError


@njit(cache=True)
def moving_average_push(buffer: np.ndarray, n: int, sample: float) -> float:
    """Store sample number n in the ring buffer and return the mean of the last k samples.

    Eq. (4.17) prints a sum over k + 1 samples; we average the last k = len(buffer) samples so
    the filter has unit DC gain (docs/deviations.md). Before k samples exist the mean is over
    the samples seen so far.
    """
    k = buffer.shape[0]
    buffer[n % k] = sample
    count = min(n + 1, k)
    total = 0.0
    for j in range(count):
        total += buffer[j]
    return total / count


def moving_average(signal: np.ndarray, order: int) -> np.ndarray:
    """The loop's causal moving average applied along the last axis of a whole signal."""
    if order < 1:
        raise ConfigError("filter_order", f"must be >= 1 (got {order}); 1 means no filtering")
    x = np.asarray(signal, dtype=float)
    csum = np.cumsum(x, axis=-1)
    n = x.shape[-1]
    lagged = np.zeros_like(csum)
    lagged[..., order:] = csum[..., : max(n - order, 0)]
    count = np.minimum(np.arange(1, n + 1), order)
    return (csum - lagged) / count
