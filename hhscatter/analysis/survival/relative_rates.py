"""Escape rates of several ensembles on one window, each with its ratio to a reference ensemble's.

Each ensemble's κ is the constant-hazard MLE on [t_start, t_stop] (events / exposure, σ = κ/√events:
:func:`~hhscatter.analysis.survival.escape_rate.escape_rate_mle`); the ratio κ/κ_ref carries both errors in
quadrature (:meth:`~hhscatter.analysis.stats.measured.Measured.ratio`), the ensembles being independent.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.survival.escape_rate import MLERate, escape_rate_mle
from hhscatter.errors import ConfigError

__all__ = ["RelativeRate", "relative_rates"]


@dataclass(frozen=True)
class RelativeRate:
    """One ensemble of :func:`relative_rates`: its MLE ``rate`` (κ in 1/time) and ``ratio`` = κ/κ_ref
    (dimensionless; None without a reference)."""

    rate: MLERate
    ratio: Measured | None


def relative_rates(samples, t_start: float, t_stop: float, ref: int | None = 0) -> list[RelativeRate]:
    """relative_rates([(t_end, escaped), …], t_start, t_stop, ref=0) -> one :class:`RelativeRate` per ensemble:
    its MLE escape rate on [t_start, t_stop] (time units) and its ratio to that of ``samples[ref]`` (no ratio
    when ``ref`` is None).

    Examples
    --------
    Two exponential ensembles of rates 0.02 and 0.03, all escaped inside the window: κ = n/Σt each, and
    κ/κ_ref = 1.5 within its error.

    >>> import numpy as np
    >>> rng = np.random.default_rng(2)
    >>> a, b = rng.exponential(50.0, 20000), rng.exponential(1 / 0.03, 20000)
    >>> rows = relative_rates([(a, np.ones(a.size, bool)), (b, np.ones(b.size, bool))], 0.0, 1e4)
    >>> rows[0].ratio.value, bool(abs(rows[1].ratio.value - 1.5) < 3 * rows[1].ratio.err)
    (1.0, True)
    """
    if not isinstance(samples, (list, tuple)) or not samples:
        raise ConfigError(f"samples must be a non-empty list of (t_end, escaped) pairs, got {type(samples).__name__}")
    for i, pair in enumerate(samples):
        if not isinstance(pair, (list, tuple)) or len(pair) != 2:
            raise ConfigError(f"samples[{i}] must be a pair (t_end, escaped), got {type(pair).__name__}")
    check.window(t_start, t_stop)
    if ref is not None and (isinstance(ref, bool) or not isinstance(ref, (int, np.integer))):
        raise ConfigError(f"ref must be an index (an integer) or None, got {ref!r}")
    if ref is not None and not -len(samples) <= ref < len(samples):
        raise ConfigError(f"ref = {ref} is not the index of one of the {len(samples)} samples")
    rates = [escape_rate_mle(t_end, escaped, t_start, t_stop) for t_end, escaped in samples]
    base = None if ref is None else rates[ref].measured("kappa")
    return [RelativeRate(r, None if base is None else r.measured("kappa") / base) for r in rates]
