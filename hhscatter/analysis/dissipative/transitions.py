"""Transition times τ1, τ2 of a dissipative ensemble: the start of enhanced trapping and the end of the escapes.

Sections III.A.2, III.B.1 and the model-data comparison of Burton, Dullin & Altmann (2023) define them:

* τ0 — end of the irregular, ensemble-dependent initial decay; independent of
  γ, an input here.
* τ1 — start of enhanced trapping, Eq. (eqn:tau1):
      τ1 = min{ t ≥ τ0 : P_γ(t) = α P_0(t) },  α > 1 (α = 2 by default).
* τ2 — end of the escape regime.  Predicted, Eq. (eq:tau2):
      τ2 = ln(E0/E_c) / (μ γ);
  observed: the first time at which the energy of a non-escaping orbit
  dropped below E_c, i.e. the smallest settling time.

The survival probability P(t) counts both ways of leaving: escape through a
channel and settling (E(t) reaching E_c inside Ω);
survival curves themselves come from :mod:`hhscatter.analysis.survival.fits`;
:func:`survival_on_grid` is a weighted, binned variant used by
:func:`bootstrap_transition_times` (paired bootstrap over orbits of τ0, τ1,
τ2 for ensembles sharing their initial conditions).

Units: model time units for all times; energies in model units.
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.least_squares import weighted_least_squares
from hhscatter.analysis.survival.fits import (
    observed_from_outcome,
    survival_from_lifetimes,
)
from hhscatter.analysis.survival.kaplan_meier import survival_on_grid
from hhscatter.errors import ConfigError

__all__ = [
    "SubsampleBootstrap",
    "bootstrap_transition_times",
    "subsample_bootstrap_transition_times",
    "settle_time_quantiles",
    "survival_on_grid",
    "power_law_exponent",
    "tau1",
    "tau1_from_lifetimes",
    "OrderStatisticInterval",
    "settle_quantile_interval",
    "tau2_observed",
    "tau2_observed_arrays",
    "tau2_observed_interval",
    "tau2_predicted",
]


# ---------------------------------------------------------------------------
# τ1
# ---------------------------------------------------------------------------


def outcome_is(outcome, value: str) -> np.ndarray:
    """outcome_is(outcome, value) -> bool array: outcome == value, without a Python string per orbit.

    ``outcome``: an array of labels, or a pandas Series/Categorical (compared on its codes: a categorical of
    1e7 orbits would otherwise become a 1e7-element object array).

    Examples
    --------
    >>> outcome_is(["escaped", "settled", "censored"], "settled").tolist()
    [False, True, False]
    >>> outcome_is(pd.Series(["escaped", "settled"], dtype="category"), "settled").tolist()
    [False, True]
    """
    import pandas as pd  # deferred: pandas loads on first use

    if isinstance(outcome, (pd.Series, pd.Categorical, pd.Index)):
        return np.array(outcome == value, dtype=bool).ravel()  # a writable copy (callers combine masks in place)
    return np.asarray(outcome).ravel() == value


def _outcomes(outcome, name: str, size: int):
    """``outcome`` if it is an array or Series of labels with one per orbit (``size``)."""
    if isinstance(outcome, (str, bytes, dict)) or outcome is None or not hasattr(outcome, "__len__"):
        raise ConfigError(f"{name} must be an array of outcome labels, got {type(outcome).__name__}")
    if len(outcome) != size:
        raise ConfigError(f"{name} must have one value per orbit: {len(outcome)} != {size}")
    return outcome


def _lifetimes(lifetimes, name: str = "lifetimes"):
    return check.table(lifetimes, name, ("t_end", "outcome"), min_rows=0)


def _log_ratio(P_gamma, P_0, alpha):
    """D = ln P_γ − ln(α P_0), with +inf where P_0 = 0 < P_γ and NaN where both vanish."""
    with np.errstate(divide="ignore", invalid="ignore"):
        D = np.log(P_gamma) - np.log(alpha * P_0)
    D = np.where((P_0 <= 0) & (P_gamma > 0), np.inf, D)
    D = np.where((P_gamma <= 0) & (P_0 > 0), -np.inf, D)
    return D


def tau1(t, P_gamma, P_0, tau0: float, alpha: float = 2.0):
    """tau1(t, P_gamma, P_0, tau0, alpha=2.0) -> float or None.

    First time t ≥ τ0 at which P_γ(t) ≥ α P_0(t), Eq. (eqn:tau1).

    ``P_gamma`` and ``P_0`` are sampled on the common grid ``t`` (increasing);
    ``P_0`` may instead be a callable P_0(t).  The crossing is located on
    the logarithmic scale: D(t) = ln P_γ − ln(α P_0) is linearly
    interpolated between the last grid point with D < 0 and the first with
    D ≥ 0 (exact for curves that are piecewise exponential between grid
    points).  D at τ0 itself is interpolated from the neighbouring points; if
    D(τ0) ≥ 0 the result is τ0.  Where P_0 = 0 < P_γ the condition counts as
    met and the crossing is put at that grid point; NaN points (e.g. beyond
    censoring) are skipped.  Returns None if the condition is never met on
    [τ0, t[-1]] (e.g. no escaping orbits left at large γ).

    Examples
    --------
    P_0 = e^{−0.1 t}, P_γ = e^{−0.05 t}: their ratio e^{0.05 t} reaches α = 2 at t = 20 ln 2 = 13.863.

    >>> t = np.arange(0.0, 51.0)
    >>> round(tau1(t, np.exp(-0.05 * t), np.exp(-0.1 * t), 0.0), 6), round(20 * math.log(2), 6)
    (13.862944, 13.862944)
    >>> tau1(t, np.exp(-0.1 * t), np.exp(-0.1 * t), 0.0) is None        # the same decay: never twice
    True
    """
    check.number(alpha, "alpha", positive=True)
    check.number(tau0, "tau0")
    t = check.numbers(t, "t", min_size=0)
    Pg = check.floats(P_gamma, "P_gamma", size=t.size, of="t")
    P0 = check.floats(P_0(t) if callable(P_0) else P_0, "P_0", size=t.size, of="t")
    if t.size and np.any(np.diff(t) <= 0):
        raise ConfigError("t must be strictly increasing")
    return _tau1(t, Pg, P0, tau0, alpha)


def _tau1(t, Pg, P0, tau0, alpha):
    """:func:`tau1` on checked arrays (the strictly increasing grid ``t``, P_γ and P_0 on it)."""
    D = _log_ratio(Pg, P0, alpha)
    keep = ~np.isnan(D)
    t, D = t[keep], D[keep]
    if t.size == 0 or t[-1] < tau0:
        return None
    # value at tau0 (log-linear interpolation between the neighbours)
    i0 = int(np.searchsorted(t, tau0, side="left"))
    if i0 < t.size and t[i0] == tau0:
        D0 = D[i0]
    elif i0 == 0:
        D0 = D[0]
        tau0 = float(t[0]) if t[0] > tau0 else tau0
    else:
        a, b = D[i0 - 1], D[i0]
        if np.isfinite(a) and np.isfinite(b):
            D0 = a + (b - a) * (tau0 - t[i0 - 1]) / (t[i0] - t[i0 - 1])
        else:
            D0 = a  # an infinite end point: keep the value left of tau0
    if D0 >= 0:
        return float(tau0)
    tt = np.concatenate([[tau0], t[t > tau0]])
    DD = np.concatenate([[D0], D[t > tau0]])
    hit = np.flatnonzero(DD >= 0)
    if hit.size == 0:
        return None
    j = int(hit[0])
    a, b = DD[j - 1], DD[j]
    if not (np.isfinite(a) and np.isfinite(b)):
        return float(tt[j])
    return float(tt[j - 1] + (tt[j] - tt[j - 1]) * (-a) / (b - a))


def tau1_from_lifetimes(
    lifetimes_gamma: pd.DataFrame, lifetimes_0: pd.DataFrame, t_grid, tau0: float, alpha: float = 2.0
):
    """tau1_from_lifetimes(lifetimes_gamma, lifetimes_0, t_grid, tau0, alpha=2.0) -> float or None.

    Observed τ1: :func:`tau1` applied to the survival
    curves of a dissipative (γ > 0) and the conservative (γ = 0) ensemble,
    both estimated on ``t_grid`` by
    :func:`hhscatter.analysis.survival.fits.survival_from_lifetimes` (Kaplan–Meier;
    'escaped' and 'settled' leave, 'censored' is right-censored).

    Examples
    --------
    The dissipative ensemble lives twice as long (rate 0.05 against 0.1): τ1 near 20 ln 2 = 13.9.

    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 20000)
    >>> lifetimes_0 = pd.DataFrame({"t_end": t, "outcome": "escaped"})
    >>> lifetimes_gamma = pd.DataFrame({"t_end": 2 * t, "outcome": "escaped"})
    >>> round(tau1_from_lifetimes(lifetimes_gamma, lifetimes_0, np.arange(0.0, 40.0, 0.5), 0.0), 1)
    13.6
    """
    _lifetimes(lifetimes_gamma, "lifetimes_gamma")
    _lifetimes(lifetimes_0, "lifetimes_0")
    check.numbers(t_grid, "t_grid", minimum=0.0)
    check.number(tau0, "tau0")
    check.number(alpha, "alpha", positive=True)
    Pg = survival_from_lifetimes(lifetimes_gamma, t_grid).P
    P0 = survival_from_lifetimes(lifetimes_0, t_grid).P
    return tau1(t_grid, Pg, P0, tau0, alpha)


# ---------------------------------------------------------------------------
# τ2
# ---------------------------------------------------------------------------
def tau2_observed_arrays(t_end, outcome):
    """tau2_observed_arrays(t_end, outcome) -> float or None.

    Observed τ2: the first time at which the energy
    of a non-escaping orbit dropped below E_c.  The engine records for a
    settled orbit the time at which E(t) reaches E_c (``t_end``), so this is
    min t_end over orbits with outcome 'settled'.  None if no orbit settled.
    Escaped orbits (whose energy also falls below E_c, but outside Ω) and
    censored orbits are not used.

    Examples
    --------
    >>> tau2_observed_arrays([5.0, 3.0, 8.0, 2.0], ["settled", "settled", "censored", "escaped"])
    3.0

    The escape at t = 2 does not count: only a settling ends the escape regime.

    >>> tau2_observed_arrays([5.0, 2.0], ["escaped", "censored"]) is None
    True
    """
    t_end = check.floats(t_end, "t_end")
    settled = outcome_is(_outcomes(outcome, "outcome", t_end.size), "settled") & np.isfinite(t_end)
    return float(t_end[settled].min()) if settled.any() else None


def tau2_observed(lifetimes: pd.DataFrame):
    """tau2_observed(lifetimes) -> float or None: min ``t_end`` over settled orbits, see :func:`tau2_observed_arrays`.

    The observed τ2: the first time at which the energy of a non-escaping orbit
    dropped below E_c.

    Examples
    --------
    >>> outcome = ["settled", "settled", "censored", "escaped"]
    >>> lifetimes = pd.DataFrame({"t_end": [5.0, 3.0, 8.0, 2.0], "outcome": outcome})
    >>> tau2_observed(lifetimes)
    3.0
    """
    _lifetimes(lifetimes)
    return tau2_observed_arrays(lifetimes["t_end"].to_numpy(), lifetimes["outcome"])


@dataclass(frozen=True)
class OrderStatisticInterval:
    """Result of :func:`settle_quantile_interval` (times in time units).

    p: the quantile of the settling-time distribution over all N orbits;
    value: the ⌈Np⌉-th settling time (the first settling time for p = 1/N);
    lo, hi: the order statistics X_(r), X_(s) bracketing the quantile, with
    X_(0) = 0 (no orbit settles before t = 0) and X_(s) = inf when fewer
    than s orbits settled; r, s their ranks; coverage: the exact probability
    P(X_(r) ≤ t_p < X_(s)) (≥ the requested level; the ranks are integers);
    n: N, n_settled.
    """

    p: float
    value: float
    lo: float
    hi: float
    r: int
    s: int
    coverage: float
    n: int
    n_settled: int


def settle_quantile_interval(t_end, outcome, p: float, level: float = 0.6826894921370859) -> OrderStatisticInterval:
    """settle_quantile_interval(t_end, outcome, p, level=0.6827) -> OrderStatisticInterval: the distribution-free
    interval [X_(r), X_(s)] of the quantile t_p of the settling time.

    The settling times of the N orbits (``outcome == 'settled'``; an orbit
    that escapes or is censored never settles: +inf) are ordered X_(1) ≤ X_(2)
    ≤ …; F(t) = P(an orbit settles before t) is defective (not every orbit
    settles) and t_p is where F = p. The number C of orbits settled before t_p
    is Binomial(N, p) whatever F is, so [X_(r), X_(s)] covers t_p exactly
    when r ≤ C ≤ s − 1: its coverage Σ_{c=r}^{s−1} Binom(c; N, p) is exact and
    distribution-free. The ranks start at the most probable count and grow on
    the side that adds more probability until the coverage reaches ``level``
    (1σ: 0.6827), so the interval covers at least that.

    For p = 1/N this is the interval of the first settling time (the
    observed τ2, a sample minimum, which estimates the quantile t_{1/N} and
    therefore depends on N): with C ≈ Poisson(1) it is [0, X_(2)], 74 % —
    the first settling time bounds the low tail from above and nothing more.
    A bootstrap of a minimum cannot give this: resampled minima are never
    below the observed one.

    Examples
    --------
    1000 orbits settling at t = 1, 2, …, 1000: the median is the 500th settling time, and the 1σ interval spans about
    ±√(1000 · 0.5 · 0.5) ≈ 16 ranks.

    >>> q = settle_quantile_interval(np.arange(1.0, 1001.0), np.full(1000, "settled"), 0.5)
    >>> q.value, q.lo, q.hi, round(q.coverage, 3)
    (500.0, 484.0, 516.0, 0.688)
    """
    from scipy import stats  # deferred: scipy loads on first use

    t_end = check.floats(t_end, "t_end")
    _outcomes(outcome, "outcome", t_end.size)
    check.number(p, "p")
    check.number(level, "level", positive=True)
    if not level < 1:
        raise ConfigError(f"level must be < 1, got {level!r}")
    settled = outcome_is(outcome, "settled") & np.isfinite(t_end)
    x = np.sort(t_end[settled])
    n = int(t_end.size)
    if not 0 < p < 1 or n == 0:
        raise ConfigError(f"p must be in (0, 1) and the ensemble not empty, got p = {p}, N = {n}")
    pmf = stats.binom(n, p).pmf
    r = s = int(np.floor((n + 1) * p))  # the mode of C: the interval [X_(r), X_(r+1)] holds C = r
    s += 1
    cov = float(pmf(r))
    while cov < level:
        left = float(pmf(r - 1)) if r > 0 else -1.0
        right = float(pmf(s)) if s <= n else -1.0
        if left >= right:
            r -= 1
            cov += left
        else:
            cov += right
            s += 1

    def order(j):
        return 0.0 if j == 0 else (float(x[j - 1]) if j <= x.size else math.inf)

    k = max(1, math.ceil(n * p - 1e-12))
    return OrderStatisticInterval(
        p=float(p), value=order(k), lo=order(r), hi=order(s), r=r, s=s, coverage=cov, n=n, n_settled=int(x.size)
    )


def tau2_observed_interval(lifetimes: pd.DataFrame, level: float = 0.6826894921370859) -> OrderStatisticInterval:
    """tau2_observed_interval(lifetimes) -> :func:`settle_quantile_interval` at p = 1/N: the observed τ2 (first
    settling time) and the order-statistic interval of the quantile it estimates.

    Examples
    --------
    The first settling time of 1000 orbits: its interval is [0, second settling time], with coverage
    P(C ≤ 1) = 2/e = 0.736 for C ≈ Poisson(1).

    >>> q = tau2_observed_interval(pd.DataFrame({"t_end": np.arange(1.0, 1001.0), "outcome": "settled"}))
    >>> q.value, q.lo, q.hi, round(q.coverage, 3)
    (1.0, 0.0, 2.0, 0.736)
    """
    if len(_lifetimes(lifetimes)) == 0:
        raise ConfigError("lifetimes must hold at least one orbit")
    return settle_quantile_interval(lifetimes["t_end"].to_numpy(), lifetimes["outcome"], 1.0 / len(lifetimes), level)


def tau2_predicted(E0, E_c, mu, gamma):
    """tau2_predicted(E0, E_c, mu, gamma) -> float or array.

    Predicted end of the escape regime, Eq. (eq:tau2):
        τ2 = ln(E0 / E_c) / (μ γ),
    the time at which the homogeneous energy law E(t) = E0 e^{−μγt}, Eq.
    (eqn:energy_exp_decay), reaches E_c.  Broadcasts over arrays.  Returns
    0 where E0 ≤ E_c (no escape regime at all) and +inf where μγ = 0 (< 0 is
    rejected).  Time in model units.

    Examples
    --------
    >>> tau2_predicted(0.3, 1 / 6, 1.0, [0.01, 0.02]).round(2).tolist()      # ln(1.8)/γ: twice the drag, half the time
    [58.78, 29.39]
    >>> tau2_predicted(0.1, 1 / 6, 1.0, 0.01)                                  # E0 below E_c: no escape regime
    0.0
    """
    check.numbers(E_c, "E_c")
    for value, name in ((E0, "E0"), (mu, "mu"), (gamma, "gamma")):
        check.floats(value, name)  # NaN (a value not measured) gives NaN
    E0, E_c, mu, gamma = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (E0, E_c, mu, gamma)))
    rate = mu * gamma
    if np.any(rate < 0) or np.any(E_c <= 0):
        raise ConfigError("need mu*gamma >= 0 and E_c > 0")
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.log(E0 / E_c) / rate
    out = np.where(E0 <= E_c, 0.0, np.where(rate == 0, np.inf, out))
    return float(out) if out.ndim == 0 else out


# ---------------------------------------------------------------------------
# survival on a grid with orbit weights, and the bootstrap of τ0, τ1, τ2
# ---------------------------------------------------------------------------
def _quantiles(qs, name: str = "qs") -> None:
    check.numbers(qs, name, minimum=0.0)
    if not np.all(np.asarray(qs, dtype=float) <= 1.0):
        raise ConfigError(f"{name} must lie in [0, 1], got {qs!r}")


def settle_time_quantiles(t_end, outcome, qs=(0.01, 0.5), weights=None):
    """settle_time_quantiles(t_end, outcome, qs=(0.01, 0.5), weights=None) -> array or None.

    (Weighted) quantiles of the settling times (t_end of 'settled' orbits):
    a robust companion of the observed τ2, whose minimum depends on the
    ensemble size N (the first of N·f_ne settlers).  None if nobody settled.

    Examples
    --------
    >>> settle_time_quantiles(np.arange(1.0, 11.0), ["settled"] * 10, qs=(0.1, 0.5)).tolist()
    [1.0, 5.0]
    >>> settle_time_quantiles(np.arange(1.0, 11.0), ["settled"] * 5 + ["escaped"] * 5, qs=(0.1, 0.5)).tolist()
    [1.0, 3.0]

    The quantiles are those of the settled orbits only (the median of 1…5 is 3).
    """
    t_end = check.floats(t_end, "t_end")
    _outcomes(outcome, "outcome", t_end.size)
    _quantiles(qs)
    if weights is not None:
        check.numbers(weights, "weights", min_size=0, minimum=0.0)
        check.floats(weights, "weights", size=t_end.size)
    return _settle_time_quantiles(t_end, outcome, qs, weights)


def _settle_time_quantiles(t_end, outcome, qs, weights):
    """:func:`settle_time_quantiles` on checked arguments (``t_end`` a flat float array)."""
    s = outcome_is(outcome, "settled")
    w = np.ones_like(t_end) if weights is None else np.asarray(weights, dtype=float).ravel()
    s &= w > 0
    if not s.any():
        return None
    order = np.argsort(t_end[s])
    ts, ws = t_end[s][order], w[s][order]
    cw = np.cumsum(ws) / ws.sum()
    idx = np.minimum(np.searchsorted(cw, np.asarray(qs, dtype=float), side="left"), ts.size - 1)
    return ts[idx]


def bootstrap_transition_times(
    curves: dict,
    reference,
    grid,
    *,
    tau0,
    alpha: float = 2.0,
    n_boot: int = 200,
    seed: int = 0,
    settle_q=(0.01, 0.5),
) -> pd.DataFrame:
    """bootstrap_transition_times(curves, reference, grid, *, tau0, alpha=2, n_boot=200, seed=0) -> DataFrame.

    Paired bootstrap over orbits of τ0, τ1 (Eq. (eqn:tau1)) and the observed τ2
    for ensembles that share their initial conditions (the same seed for
    every γ): each replicate gives orbit i the same
    Poisson(1) multiplicity in every ensemble, so the correlation between
    P_γ and P_0 built from the same orbits is kept.

    ``curves``: {label: (t_end, outcome)} with arrays aligned by orbit (same
    length N, same order); ``reference``: the label of the conservative
    ensemble (P_0).  ``tau0``: a float, or a callable ``tau0(grid, P_0, n)``
    returning τ0 from the replicate's P_0 (n = effective ensemble size) —
    e.g. the data-driven rule of :func:`hhscatter.analysis.survival.windows.choose_windows`.
    Returns one row per (replicate, label != reference): ``replicate, label,
    tau0, tau1, tau2_obs, t_settle_q<q>...`` (NaN where undefined).

    Examples
    --------
    The same 2000 orbits with and without drag, the dissipative lifetimes twice as long: τ1 near 20 ln 2 = 13.9, with
    the bootstrap spread its statistical error (nobody settles here: τ2 is NaN).

    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 2000)
    >>> curves = {0.0: (t, np.full(t.size, "escaped")), 0.01: (2 * t, np.full(t.size, "escaped"))}
    >>> b = bootstrap_transition_times(curves, 0.0, np.arange(0.0, 40.0, 0.5), tau0=0.0, n_boot=50)
    >>> len(b), round(float(b["tau1"].mean()), 1), round(float(b["tau1"].std()), 1), bool(b["tau2_obs"].isna().all())
    (50, 13.2, 0.5, True)
    """
    check.mapping(curves, "curves", min_size=1)
    if not isinstance(reference, Hashable) or reference not in curves:
        raise ConfigError(f"reference {reference!r} is not one of the curves {list(curves)}")
    check.count(n_boot, "n_boot", 1)
    check.numbers(grid, "grid", minimum=0.0)
    if not callable(tau0):
        check.number(tau0, "tau0")
    check.number(alpha, "alpha", positive=True)
    _quantiles(settle_q, "settle_q")
    for lab, pair in curves.items():
        if isinstance(pair, (str, bytes, dict)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise ConfigError(f"curves[{lab!r}] must be a pair (t_end, outcome), got {type(pair).__name__}")
        _outcomes(pair[1], f"curves[{lab!r}] outcome", check.numbers(pair[0], f"curves[{lab!r}] t_end").size)
    arrs = {}
    n = None
    for lab, (t_end, outcome) in curves.items():
        t_end = np.asarray(t_end, dtype=float).ravel()
        outcome = np.asarray(outcome).ravel()
        if n is None:
            n = t_end.size
        if t_end.size != n or outcome.size != n:
            raise ConfigError(f"curve {lab!r} has {t_end.size} orbits, expected {n} (paired ensembles)")
        arrs[lab] = (t_end, outcome, observed_from_outcome(outcome))
    g = np.asarray(grid, dtype=float)
    if len(curves) > 1 and g.size and np.any(np.diff(g.ravel()) <= 0):
        raise ConfigError("grid must be strictly increasing")
    rng = np.random.default_rng(seed)
    qcols = [f"t_settle_q{q:g}" for q in settle_q]
    rows = []
    for b in range(n_boot):
        w = rng.poisson(1.0, n).astype(float)
        t_r, _, obs_r = arrs[reference]
        P0 = survival_on_grid(t_r, obs_r, g, w)
        t0 = float(tau0(g, P0, float(w.sum()))) if callable(tau0) else float(tau0)
        for lab, (t_end, outcome, obs) in arrs.items():
            if lab == reference:
                continue
            Pg = survival_on_grid(t_end, obs, g, w)
            t1 = _tau1(g, Pg, P0, t0, alpha)
            sel = (outcome == "settled") & (w > 0)
            t2 = float(t_end[sel].min()) if sel.any() else np.nan
            qv = _settle_time_quantiles(t_end, outcome, settle_q, w)
            row = {"replicate": b, "label": lab, "tau0": t0, "tau1": np.nan if t1 is None else t1, "tau2_obs": t2}
            vals = [np.nan] * len(qcols) if qv is None else [float(v) for v in qv]
            row.update(dict(zip(qcols, vals)))
            rows.append(row)
    return pd.DataFrame(rows, columns=["replicate", "label", "tau0", "tau1", "tau2_obs", *qcols])


@dataclass(frozen=True)
class SubsampleBootstrap:
    """The paired bootstrap of :func:`bootstrap_transition_times` on the first ``n_orbits`` of ``n_total`` orbits.

    ``replicates``: its DataFrame; ``scale`` = √(n_orbits/n_total), the factor that carries a standard deviation
    of the subsample to the whole ensemble (σ ∝ 1/√N); :meth:`err` applies it.
    """

    replicates: pd.DataFrame
    n_orbits: int
    n_total: int

    @property
    def scale(self) -> float:
        """√(n_orbits / n_total): σ of the subsample → σ of the whole ensemble."""
        return float(np.sqrt(self.n_orbits / self.n_total))

    def err(self, column: str) -> float:
        """The whole ensemble's 1σ error of ``column`` (same unit): the replicates' standard deviation × scale."""
        return float(self.replicates[column].std(ddof=1)) * self.scale


def subsample_bootstrap_transition_times(
    lifetimes: dict, reference, grid, *, n_orbits: int, **kw
) -> SubsampleBootstrap:
    """The paired bootstrap of τ0, τ1, τ2 on the first ``n_orbits`` orbits, its σ scaled to the whole ensemble.

    ``lifetimes``: {label: DataFrame with t_end (time units) and outcome}, rows aligned by orbit (the same N for
    every label); the bootstrap (:func:`bootstrap_transition_times` with ``reference``, ``grid`` and ``kw``) runs
    on the first K = min(``n_orbits``, N) rows, and a standard deviation σ_K of its replicates stands for
    σ_K √(K/N) over all N orbits (:class:`SubsampleBootstrap`). The rows are sliced before their conversion to
    arrays, so a large table's outcome column is never converted whole.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 4000)
    >>> lt = {0.0: pd.DataFrame({"t_end": t, "outcome": "escaped"}),
    ...       0.01: pd.DataFrame({"t_end": 0.8 * t, "outcome": "escaped"})}
    >>> b = subsample_bootstrap_transition_times(lt, 0.0, np.arange(0.0, 50.0, 0.5), n_orbits=1000, tau0=1.0,
    ...                                          n_boot=20, seed=1)
    >>> b.n_orbits, b.scale, len(b.replicates)
    (1000, 0.5, 20)
    """
    check.mapping(lifetimes, "lifetimes", min_size=1)
    for label, lt in lifetimes.items():
        _lifetimes(lt, f"lifetimes[{label!r}]")
    check.count(n_orbits, "n_orbits", 1)
    N = len(next(iter(lifetimes.values())))
    K = min(n_orbits, N)
    curves = {g: (lt["t_end"].iloc[:K].to_numpy(), lt["outcome"].iloc[:K].to_numpy()) for g, lt in lifetimes.items()}
    return SubsampleBootstrap(bootstrap_transition_times(curves, reference, grid, **kw), K, N)


def power_law_exponent(gamma, tau, tau_err):
    """power_law_exponent(gamma, tau, tau_err) -> (p, σ_p) of τ ∝ γ^−p, or (None, None) with < 2 usable points.

    Weighted least squares of log τ = c − p log γ over the finite τ > 0 (γ > 0),
    weights 1/(σ_τ/τ)² (points without a usable error get the largest error of
    the others); σ_p inflated by the reduced χ² when the points scatter more
    than their errors. With no usable error at all the fit is unweighted and
    σ_p comes from the residual scatter. E.g. τ2 ∝ 1/γ, Eq. (eq:tau2), is p = 1.

    Examples
    --------
    τ = 1/γ with 5 % errors: p = 1, σ_p = 0.05/(√2 ln 2) = 0.051.

    >>> p, p_err = power_law_exponent([0.01, 0.02, 0.04], [100.0, 50.0, 25.0], [5.0, 2.5, 1.25])
    >>> round(p, 9), round(p_err, 3)
    (1.0, 0.051)
    """
    g = check.floats(gamma, "gamma")
    t = check.floats(tau, "tau", size=g.size, of="gamma")
    e = check.floats(tau_err, "tau_err", size=g.size, of="gamma")
    ok = np.isfinite(t) & (t > 0) & (g > 0)
    if ok.sum() < 2:
        return None, None
    x, y = np.log(g[ok]), np.log(t[ok])
    s = e[ok] / t[ok]
    good = np.isfinite(s) & (s > 0)
    if not good.any():  # no errors at all: an unweighted fit, its error from the residual scatter
        fit = weighted_least_squares(np.column_stack([np.ones_like(x), x]), y, np.ones_like(y), errors="scaled")
        return float(-fit.coef[1]), float(fit.err[1])
    s = np.where(good, s, s[good].max())
    fit = weighted_least_squares(np.column_stack([np.ones_like(x), x]), y, 1.0 / s**2, errors="inflated")
    return float(-fit.coef[1]), float(fit.err[1])
