"""Binomial fractions: Wilson score intervals (model-free; used by the exit-channel and basin measures) and a
fraction reported with its error, or, at a count of 0 or of all, with its one-sided bound (never "0 ± 0"); a Poisson
rate with no event in its exposure by its one-sided bound (:func:`rate_upper_bound`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["BoundedFraction", "fraction_with_bound", "rate_upper_bound", "wilson_interval"]


def wilson_interval(k, n, z: float = 1.0):
    """wilson_interval(k, n, z=1.0) -> (p, lo, hi): fraction k/n and its Wilson score interval.

    ``z`` is the normal quantile (1 → ±1σ, 68.3 %; 1.96 → 95 %).  Works on
    arrays; n = 0 gives NaN.  The Wilson interval stays inside [0, 1] and is
    honest for k = 0 or k = n (where the Wald interval p ± z√(p(1−p)/n) has
    zero width):  centre (p + z²/2n)/(1 + z²/n), half-width
    z√(p(1−p)/n + z²/4n²)/(1 + z²/n).

    Examples
    --------
    >>> p, lo, hi = wilson_interval(0, 10)      # no success in 10: the upper end is z²/(n + z²) = 1/11
    >>> float(p), float(lo), round(float(hi), 4)
    (0.0, 0.0, 0.0909)
    >>> p, lo, hi = wilson_interval([5, 50], [10, 100])    # the same fraction, ten times the trials: ≈ √10 narrower
    >>> p.tolist(), lo.round(4).tolist(), hi.round(4).tolist()
    ([0.5, 0.5], [0.3492, 0.4502], [0.6508, 0.5498])
    """
    check.numbers(k, "k", minimum=0.0)
    check.numbers(n, "n", minimum=0.0)
    check.number(z, "z", positive=True)
    k = np.asarray(k, dtype=float)
    n = np.asarray(n, dtype=float)
    if np.any(k < 0) or np.any(k > n):
        raise ConfigError("need 0 ≤ k ≤ n")
    if not z > 0:
        raise ConfigError(f"z must be > 0, got {z}")
    with np.errstate(divide="ignore", invalid="ignore"):
        p = k / n
        d = 1.0 + z * z / n
        c = (p + z * z / (2 * n)) / d
        h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return p, c - h, c + h


@dataclass(frozen=True)
class BoundedFraction:
    """Result of :func:`fraction_with_bound`: a fraction k/n with its 1σ error, or its one-sided bound at k = 0 or
    k = n.

    Attributes
    ----------
    k, n : int
        The count and the number of trials.
    value : float
        k/n.
    err : float or None
        The 1σ error (binomial √(f(1 − f)/n), at least the Wilson 1σ half-width) for 0 < k < n; None at k = 0 or
        k = n, where the fraction is reported by its bound instead.
    upper, lower : float or None
        The one-sided bound at confidence ``cl``: ``upper`` at k = 0, ``lower`` at k = n (None otherwise).
    cl : float
        The confidence level of the bound.
    """

    k: int
    n: int
    value: float
    err: float | None
    upper: float | None
    lower: float | None
    cl: float

    def record(self, prefix: str = "") -> dict:
        """The JSON fields ``{prefix}value``-style: ``{"value", "err"}`` plus ``"upper"``/``"lower"`` and ``"cl"``
        where the count is 0 or n (with a ``prefix`` the keys are ``prefix``, ``prefix_err``, ``prefix_upper``…).

        >>> fraction_with_bound(0, 1000).record("P")
        {'P': 0.0, 'P_err': None, 'P_upper': 0.002991, 'P_cl': 0.95}
        """
        key = (lambda s: f"{prefix}_{s}") if prefix else (lambda s: s)
        out = {prefix or "value": self.value, key("err"): self.err}
        if self.upper is not None:
            out[key("upper")] = round(self.upper, 6)
        if self.lower is not None:
            out[key("lower")] = round(self.lower, 6)
        if self.upper is not None or self.lower is not None:
            out[key("cl")] = self.cl
        return out


def fraction_with_bound(k: int, n: int, *, cl: float = 0.95) -> BoundedFraction:
    """fraction_with_bound(k, n, cl=0.95) -> BoundedFraction: the fraction k/n of n trials, with its 1σ error for
    0 < k < n and its exact one-sided bound at confidence ``cl`` at k = 0 (upper: 1 − (1 − cl)^(1/n), the
    Clopper–Pearson bound, ≈ 3/n at 95 %) or k = n (lower: (1 − cl)^(1/n)); a count of 0 is never "0 ± 0".

    The error for 0 < k < n is the binomial √(f(1 − f)/n), at least the Wilson 1σ half-width (which stays
    nonzero near 0 and 1).

    Examples
    --------
    >>> f = fraction_with_bound(0, 10000)
    >>> f.value, f.err, round(f.upper, 7)        # 1 − 0.05^(1/10000)
    (0.0, None, 0.0002995)
    >>> f = fraction_with_bound(250, 1000)
    >>> round(f.err, 5), f.upper                 # √(0.25 · 0.75 / 1000)
    (0.01369, None)
    >>> round(fraction_with_bound(20, 20).lower, 4)
    0.8609
    """
    k = int(check.number(k, "k", minimum=0.0))
    n = int(check.number(n, "n", positive=True))
    check.number(cl, "cl")
    if n <= 0:
        raise ConfigError(f"n must be a positive number of trials, got {n}")
    if not 0 <= k <= n:
        raise ConfigError(f"k must lie in [0, n] = [0, {n}], got {k}")
    if not 0 < cl < 1:
        raise ConfigError(f"cl must lie in (0, 1), got {cl}")
    f = k / n
    if k == 0:
        return BoundedFraction(k, n, 0.0, None, -math.expm1(math.log1p(-cl) / n), None, cl)
    if k == n:
        return BoundedFraction(k, n, 1.0, None, None, math.exp(math.log1p(-cl) / n), cl)
    wilson = math.sqrt(f * (1 - f) / n + 1 / (4 * n * n)) / (1 + 1 / n)
    return BoundedFraction(k, n, f, max(math.sqrt(f * (1 - f) / n), wilson), None, None, cl)


def rate_upper_bound(exposure, cl: float = 0.95):
    """rate_upper_bound(exposure, cl=0.95) -> the one-sided upper bound (1/time) at confidence ``cl`` of a Poisson
    rate with no event in ``exposure`` (orbit-time at risk, time units): −ln(1 − cl)/exposure, the rate at which
    no event has probability 1 − cl (≈ 3/exposure at 95 %); inf at zero exposure. Works on arrays.

    A rate estimated as events/exposure with its Poisson error √events/exposure is "0 ± 0" at 0 events; this bound
    is what such a bin reports instead.

    Examples
    --------
    >>> round(rate_upper_bound(1000.0), 6)            # −ln(0.05)/1000
    0.002996
    >>> rate_upper_bound([100.0, 0.0]).round(4).tolist()
    [0.03, inf]
    """
    check.numbers(exposure, "exposure", minimum=0.0)
    if not 0 < check.number(cl, "cl") < 1:
        raise ConfigError(f"cl must lie in (0, 1), got {cl}")
    x = np.asarray(exposure, dtype=float)
    if np.any(x < 0):
        raise ConfigError("exposure must be ≥ 0")
    with np.errstate(divide="ignore"):
        out = np.where(x > 0, -math.log1p(-cl) / np.where(x > 0, x, 1.0), np.inf)
    return float(out) if out.ndim == 0 else out
