"""Binomial fractions with Wilson score intervals (model-free; used by the exit-channel and basin measures)."""

from __future__ import annotations

import numpy as np

__all__ = ["wilson_interval"]


def wilson_interval(k, n, z: float = 1.0):
    """wilson_interval(k, n, z=1.0) -> (p, lo, hi): fraction k/n and its Wilson score interval.

    ``z`` is the normal quantile (1 → ±1σ, 68.3 %; 1.96 → 95 %).  Works on
    arrays; n = 0 gives NaN.  The Wilson interval stays inside [0, 1] and is
    honest for k = 0 or k = n (where the Wald interval p ± z√(p(1−p)/n) has
    zero width):  centre (p + z²/2n)/(1 + z²/n), half-width
    z√(p(1−p)/n + z²/4n²)/(1 + z²/n).
    """
    k = np.asarray(k, dtype=float)
    n = np.asarray(n, dtype=float)
    if np.any(k < 0) or np.any(k > n):
        raise ValueError("need 0 ≤ k ≤ n")
    if not z > 0:
        raise ValueError(f"z must be > 0, got {z}")
    with np.errstate(divide="ignore", invalid="ignore"):
        p = k / n
        d = 1.0 + z * z / n
        c = (p + z * z / (2 * n)) / d
        h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return p, c - h, c + h
