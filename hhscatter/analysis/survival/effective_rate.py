"""The effective escape rate of a dissipative ensemble against κ0 at the decayed energy.

For small γ, Burton, Dullin & Altmann (2023) describe escape from the dissipative system by the conservative rate at the current
energy, κγ(t) = κ0(E(t)), E(t) = E0 e^{−μγt} (Eq. (eqn:energy_exp_decay)); this is what their survival model,
Eq. (eqn:surv_prob_model), integrates. Pure functions (no I/O):

* :func:`binned_hazard` — the escape hazard in time bins: escapes in the bin over the time the orbits spent
  at risk in it (orbits leave the risk set when they escape, settle or are censored), with its Poisson error, or,
  in a bin with no escape, its one-sided 95 % upper bound (never "0 ± 0");
* :func:`observed_over_expected` — Σ escapes / Σ κ0(E(t)) · exposure over the bins: 1 when the hazard is
  κ0(E(t)), with the Poisson error of the observed count.

Units: t in time units, hazard and κ in 1/time.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import rate_upper_bound
from hhscatter.errors import ConfigError

__all__ = ["binned_hazard", "observed_over_expected"]


def binned_hazard(t_end, escaped, edges) -> pd.DataFrame:
    """binned_hazard(t_end, escaped, edges) -> DataFrame[t_lo, t_hi, t_mid, events, exposure, hazard, hazard_err,
    hazard_upper].

    ``t_end``: each orbit's end time (escape, settling or censoring); ``escaped``: True where it ended by escape.
    Per bin [t_lo, t_hi): events = escapes in it, exposure = Σ_i |[t_lo, t_hi) ∩ [0, t_end_i)| (orbit-time at
    risk), hazard = events/exposure (1/time: the maximum-likelihood constant rate of the bin), hazard_err =
    √events/exposure. A bin with orbits at risk but no escape has hazard 0, no error (NaN) and its one-sided 95 %
    upper bound hazard_upper = −ln(0.05)/exposure (escapes ~ Poisson in the exposure:
    :func:`~hhscatter.analysis.stats.intervals.rate_upper_bound`); hazard_upper is NaN elsewhere. A bin with no
    orbit at risk has NaN throughout.

    Examples
    --------
    >>> import numpy as np
    >>> d = binned_hazard(np.array([1.0, 3.0, 5.0]), np.array([True, True, False]), [0.0, 2.0, 4.0, 6.0])
    >>> d[["events", "exposure"]].to_numpy().tolist()
    [[1.0, 5.0], [1.0, 3.0], [0.0, 1.0]]
    >>> d["hazard_upper"].round(3).tolist()    # no escape in [4, 6): hazard < −ln(0.05)/1
    [nan, nan, 2.996]
    """
    t = check.numbers(t_end, "t_end", min_size=0)
    e = check.mask(escaped, "escaped", t.size)
    edges_ = check.numbers(edges, "edges", min_size=2)
    if np.ndim(edges) != 1 or np.any(np.diff(edges_) <= 0):
        raise ConfigError("edges must be increasing, at least 2 of them")
    edges = edges_
    lo, hi = edges[:-1], edges[1:]
    ts = np.sort(t)
    # exposure = Σ_i clip(t_i − lo, 0, hi − lo) = ∫_lo^hi N(s > t) dt, by the sorted times' cumulative sums
    cum = np.concatenate([[0.0], np.cumsum(ts)])

    def integral_alive(x):  # ∫_0^x #{t_i > s} ds = Σ_i min(t_i, x)
        k = np.searchsorted(ts, x, side="right")
        return cum[k] + x * (ts.size - k)

    exposure = integral_alive(hi) - integral_alive(lo)
    events = np.histogram(t[e], bins=edges)[0].astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        h = np.where(exposure > 0, events / exposure, np.nan)
        err = np.where((exposure > 0) & (events > 0), np.sqrt(events) / exposure, np.nan)
    upper = np.where((exposure > 0) & (events == 0), rate_upper_bound(exposure), np.nan)
    return pd.DataFrame(
        {
            "t_lo": lo,
            "t_hi": hi,
            "t_mid": 0.5 * (lo + hi),
            "events": events,
            "exposure": exposure,
            "hazard": h,
            "hazard_err": err,
            "hazard_upper": upper,
        }
    )


def observed_over_expected(bins: pd.DataFrame, rate) -> tuple[float, float, float]:
    """observed_over_expected(bins, rate) -> (O/E, σ, expected events) over the bins of :func:`binned_hazard`.

    ``rate``: the predicted hazard per bin (e.g. κ0(E0 e^{−μγ t_mid})); bins with a non-finite rate are left out.
    O/E = Σ events / Σ rate·exposure, σ = √(Σ events)/Σ rate·exposure (Poisson).

    Examples
    --------
    >>> import pandas as pd
    >>> b = pd.DataFrame({"events": [10.0, 30.0], "exposure": [100.0, 200.0]})
    >>> observed_over_expected(b, [0.1, 0.15])[:2]
    (1.0, 0.15811388300841897)
    """
    if not isinstance(bins, pd.DataFrame) or not {"events", "exposure"} <= set(bins.columns):
        raise ConfigError("bins must be a DataFrame with the columns events and exposure (binned_hazard)")
    r = np.asarray(rate) if not isinstance(rate, (str, bytes, dict)) and rate is not None else np.array("x")
    if r.dtype == bool or r.dtype.kind not in "iuf":
        raise ConfigError(f"rate must be an array of numbers (one per bin), got {type(rate).__name__}")
    if r.ndim > 1 or (r.ndim == 1 and r.size != len(bins)):
        raise ConfigError(f"rate must hold one value per bin: {r.size} != {len(bins)}")
    r = r.astype(float)
    ok = np.isfinite(r)
    exp_ = float(np.sum(r[ok] * bins["exposure"].to_numpy()[ok]))
    obs = float(np.sum(bins["events"].to_numpy()[ok]))
    if exp_ <= 0:
        return math.nan, math.nan, 0.0
    return obs / exp_, math.sqrt(obs) / exp_, exp_
