"""Moving-average filter of order k on a sampled signal, Eq. (4.17) taken as a mean."""

from __future__ import annotations

import numpy as np

from articula.errors import ConfigError
from articula.numba_cache import jit


@jit(error_model="numpy")
def moving_average_push(buffer: np.ndarray, n: int, samples: np.ndarray, means: np.ndarray) -> None:
    """Store sample number n of each column and write the mean of its last k samples.

    Eq. (4.17) prints a sum over k + 1 samples; we average the last k samples so that the
    filter has unit DC gain (docs/deviations.md). The buffer starts at zero, as in firmware:
    the samples before the start count as 0 A, which they are for a motor at rest.

    Args:
        buffer: ring buffer of the last k samples, shape (k, batch), updated in place.
        n: index of this sample (0 for the first); its slot in the ring is n mod k.
        samples: the new sample of each trial, shape (batch,).
        means: output, written in place: the filtered value of each trial, shape (batch,).
    """
    k, batch = buffer.shape
    slot = n % k
    for b in range(batch):
        buffer[slot, b] = samples[b]
        means[b] = 0.0
    for j in range(k):
        for b in range(batch):
            means[b] += buffer[j, b]
    for b in range(batch):
        means[b] /= k


def moving_average(signal: np.ndarray, order: int) -> np.ndarray:
    """The loop's causal moving average along the last axis of a whole signal (zero history).

    Args:
        signal: sampled signal, shape (..., n); filtered along the last axis.
        order: filter order k, the number of samples averaged (1 = no filtering).

    Returns:
        The filtered signal, same shape as `signal`.
    """
    if order < 1:
        raise ConfigError("filter_order", f"must be >= 1 (got {order}); 1 means no filtering")
    x = np.asarray(signal, dtype=float)
    csum = np.cumsum(x, axis=-1)
    n = x.shape[-1]
    lagged = np.zeros_like(csum)
    lagged[..., order:] = csum[..., : max(n - order, 0)]
    return (csum - lagged) / order
