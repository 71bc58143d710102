"""Survival probability P(t) and its exponential / power-law regimes.

Sec. II of Burton, Dullin & Altmann (2023) describes the survival probability of an ensemble started in the
scattering region Ω as

* Eq. (eqn:kappa_hyperbolic), hyperbolic saddles:
      P(t) = irregular for t ∈ [0, τ0],   P(t) = f0 e^{−κ t} for t > τ0;
* Eq. (eqn:kappa_nonhyperbolic), mixed phase space (stickiness):
      P(t) ~ irregular (t < τ0),  f0 e^{−κ t} (τ0 < t < τ*),  f* t^{−z} (t > τ*).

Functions here are pure (no file I/O, no plotting) and vectorised:

* :func:`survival_curve` — Kaplan–Meier estimate of P(t) with Greenwood errors
  from lifetimes ``t_end`` and a boolean ``observed`` mask (False = right-censored)
  (defined in :mod:`hhscatter.analysis.survival.kaplan_meier`, the one estimator);
* :func:`lifetimes_to_arrays`, :func:`survival_from_lifetimes` — the same from
  the engine's ``lifetimes`` table;
* :func:`fit_exponential` — least squares of log P on t (κ, f0);
* :func:`mean_kappa_stat_err` — statistical error of a mean of such fits over
  overlapping windows;
* :func:`fit_power_law_tail` — least squares of log P on log t (z, f*);
* :func:`crossover_time` — τ*, where the fitted exponential and power law meet;
* :func:`detect_power_law_tail` — data-driven decision "is there a power-law
  tail after τ0?", returning the tail fit or None.

Conventions.  An orbit *leaves* Ω at ``t_end`` if its outcome is 'escaped' or
'settled' (both count as leaving);
'censored' orbits were still inside at ``t_end`` = t_max and are right-censored.
P(t) = Pr(lifetime > t) is right-continuous.  Times are in the model's natural
time units (unit mass, ω = λ = 1); κ is in 1/time; z, f0 are dimensionless and
f* has units time^z.

Error model.  Kaplan–Meier log-survival estimates at different times are
strongly positively correlated (log S(t) is, to leading order, a sum of
independent increments with variance V(t) = Greenwood's cumulative sum).  The
least-squares fits below use diagonal weights 1/σ²(log P) for the point
estimate, but report the *correct* standard error of that linear estimator
under the independent-increment covariance Cov(log P_i, log P_j) = V(min(t_i,t_j))
(``kappa_err`` / ``z_err``); the naive diagonal-weight error, which ignores the
correlations and is far too small on a fine grid, is kept as ``*_err_naive``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy import optimize
from scipy.special import xlogy

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.least_squares import (
    least_squares_operator,
    weighted_least_squares,
)
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.analysis.survival.kaplan_meier import SurvivalCurve, survival_curve
from hhscatter.errors import ConfigError
from hhscatter.outcomes import CENSORED, CENSORING_OUTCOMES, LEAVING_OUTCOMES, OUTCOMES

__all__ = [
    "CENSORED_OUTCOME",
    "CENSORING_OUTCOMES",
    "LEAVING_OUTCOMES",
    "ExponentialFit",
    "PowerLawFit",
    "SurvivalCurve",
    "crossover_time",
    "detect_power_law_tail",
    "fit_exponential",
    "fit_power_law_tail",
    "lifetimes_to_arrays",
    "mean_kappa_stat_err",
    "observed_from_outcome",
    "survival_curve",
    "survival_from_lifetimes",
]

# 'stopped': the engine stopped the orbit because nothing more was needed from it
# (hhscatter.integrate.events); for a lifetime it is right-censoring at t_end, like 'censored'
CENSORED_OUTCOME = OUTCOMES[CENSORED]


# ---------------------------------------------------------------------------
# Kaplan–Meier survival curve: hhscatter.analysis.survival.kaplan_meier (the one estimator), lifetimes tables in
# ---------------------------------------------------------------------------
def observed_from_outcome(outcome) -> np.ndarray:
    """observed_from_outcome(outcome) -> bool array: True for 'escaped'/'settled', False for 'censored'/'stopped'.

    Raises ValueError on any other (or missing) outcome label. A pandas categorical is mapped through its
    categories (one label test per category, then the codes: no Python object per orbit).

    Examples
    --------
    >>> observed_from_outcome(["escaped", "settled", "censored", "stopped"]).tolist()
    [True, True, False, False]
    >>> import pandas as pd
    >>> observed_from_outcome(pd.Series(["censored", "escaped"], dtype="category")).tolist()
    [False, True]
    """
    import pandas as pd  # deferred: pandas loads on first use

    cat = outcome.array if isinstance(outcome, pd.Series) else outcome
    if isinstance(cat, pd.Categorical):
        labels = np.asarray(cat.categories, dtype=object)
        leaving_c = np.isin(labels, LEAVING_OUTCOMES)
        bad_c = ~(leaving_c | np.isin(labels, CENSORING_OUTCOMES))
        codes = np.asarray(cat.codes)
        if (codes < 0).any() or bad_c[codes].any():
            seen = {repr(v) for v in labels[np.unique(codes[codes >= 0])][bad_c[np.unique(codes[codes >= 0])]]}
            raise ConfigError(f"unknown outcome labels: {sorted(seen | ({'nan'} if (codes < 0).any() else set()))[:5]}")
        return leaving_c[codes]
    o = np.asarray(outcome, dtype=object).ravel()
    leaving = np.isin(o, LEAVING_OUTCOMES)
    censored = np.isin(o, CENSORING_OUTCOMES)
    bad = ~(leaving | censored)
    if bad.any():
        raise ConfigError(f"unknown outcome labels: {sorted({repr(v) for v in o[bad]})[:5]}")
    return leaving


def lifetimes_to_arrays(lifetimes, *, check_single_ensemble: bool = True):
    """lifetimes_to_arrays(lifetimes) -> (t_end float64 array, observed bool array).

    Converts the engine's ``lifetimes`` table (columns ``t_end``, ``outcome``;
    optionally ``e0``, ``gamma``) to the arrays used by the survival functions.
    With ``check_single_ensemble`` a table mixing several ensembles (grid
    points: values of ``energy``, ``gamma`` or, beyond the last bits, ``e0``)
    raises ValueError: analyse all points with :func:`hhscatter.survival` /
    :func:`hhscatter.escape_rates`, or select one first, e.g.
    ``lifetimes.groupby(['energy', 'gamma'])`` (never by ``e0``, which
    differs from orbit to orbit in the last bits).

    Examples
    --------
    >>> import pandas as pd
    >>> lifetimes = pd.DataFrame({"t_end": [1.0, 2.0, 5.0], "outcome": ["escaped", "settled", "censored"]})
    >>> t_end, observed = lifetimes_to_arrays(lifetimes)
    >>> t_end.tolist(), observed.tolist()
    ([1.0, 2.0, 5.0], [True, True, False])
    """
    check.table(lifetimes, "lifetimes", ("t_end", "outcome"), min_rows=0)
    if check_single_ensemble:
        for col in ("energy", "e0", "gamma"):
            # e0 is recomputed from each initial state, so one ensemble's values differ in the
            # last bits: compare with a relative tolerance, not by exact uniqueness
            v = lifetimes[col].to_numpy(dtype=float) if col in lifetimes.columns else np.zeros(0)
            if v.size and (np.isnan(v).any() or np.ptp(v) > 1e-9 * max(1.0, float(np.max(np.abs(v))))):
                raise ConfigError(
                    f"lifetimes mixes several values of {col!r} (several grid points): use hhscatter.survival"
                    "(lifetimes) / hhscatter.escape_rates(lifetimes) for one result per point, or select one "
                    "point, e.g. lifetimes.groupby(['energy', 'gamma']) (not by 'e0', which differs per orbit)"
                )
    t_end = lifetimes["t_end"].to_numpy(dtype=float)
    observed = observed_from_outcome(lifetimes["outcome"].astype(object).to_numpy())
    return t_end, observed


def survival_from_lifetimes(lifetimes, t_grid=None) -> SurvivalCurve:
    """survival_from_lifetimes(lifetimes, t_grid=None) -> SurvivalCurve(t, P, P_err).

    DataFrame wrapper of :func:`survival_curve` for one ensemble of the engine's
    ``lifetimes`` table ('escaped' and 'settled' leave, 'censored' is censored):
    P(t), the fraction of the ensemble still inside Ω at t (with drag, settling
    also ends a lifetime).

    Examples
    --------
    >>> import pandas as pd
    >>> outcome = ["escaped", "escaped", "censored", "censored"]
    >>> c = survival_from_lifetimes(pd.DataFrame({"t_end": [1.0, 2.0, 3.0, 4.0], "outcome": outcome}), [0.5, 1.5, 2.5])
    >>> c.P.round(12).tolist()              # 4, 3, then 2 of the 4 orbits still inside
    [1.0, 0.75, 0.5]
    """
    t_end, observed = lifetimes_to_arrays(lifetimes)
    return survival_curve(t_end, observed, t_grid)


# ---------------------------------------------------------------------------
# least-squares fits of log P
# ---------------------------------------------------------------------------
def _independent_increment_cov(rows, V):
    """Cov of linear functionals rows @ y when y_i = y_0 + Σ_{k≤i} e_k, Var(y_0) = V[0], Var(e_k) = ΔV_k.

    ``rows`` (m, n) with the points sorted in time; ``V`` (n,) non-decreasing.
    Cov(a·y, b·y) = (Σa)(Σb) V_0 + Σ_k ΔV_k A_k B_k, A_k = Σ_{i ≥ k} a_i.
    """
    V = np.maximum.accumulate(np.asarray(V, dtype=float))
    dV = np.diff(V)
    tails = np.cumsum(rows[:, ::-1], axis=1)[:, ::-1]  # A_k = Σ_{i≥k} a_i
    tot = tails[:, 0]
    inc = tails[:, 1:]
    return np.outer(tot, tot) * V[0] + (inc * dV) @ inc.T


def _fit_log_linear(x, y, sigma_y):
    """Fit y = α + β x; returns (β, α, cov_corr, cov_naive, n, rms) with cov order (β, α).

    With ``sigma_y`` (Greenwood σ of log P, points sorted in time) the fit is
    weighted by 1/σ², cov_corr uses the independent-increment covariance
    V_i = σ_i², cov_naive the diagonal one.  Without it, ordinary least squares
    with residual-scaled diagonal errors (cov_corr = cov_naive).
    """
    n = x.size
    X = np.column_stack([x, np.ones(n)])
    if sigma_y is None:
        fit = weighted_least_squares(X, y, errors="scaled")
        cov_naive = cov_corr = fit.cov
    else:
        fit = weighted_least_squares(X, y, 1.0 / sigma_y**2)
        cov_naive = fit.cov
        cov_corr = _independent_increment_cov(fit.operator, sigma_y**2)
    beta, alpha = fit.coef
    rms = float(np.sqrt(np.mean(fit.resid**2)))
    return float(beta), float(alpha), cov_corr, cov_naive, n, rms


def _prepare(t, P, P_err, window, log_t):
    t = check.floats(t, "t")
    P = check.floats(P, "P", size=t.size, of="t")
    if P_err is not None:
        check.floats(P_err, "P_err", size=t.size, of="t")
    lo, hi = check.interval(window, "window")
    m = (t >= lo) & (t <= hi) & np.isfinite(t) & np.isfinite(P) & (P > 0)
    if log_t:
        m &= t > 0
    sig = None
    if P_err is not None:
        P_err = np.asarray(P_err, dtype=float).ravel()
        if P_err.shape != P.shape:
            raise ConfigError("P_err and P differ in length")
        m &= np.isfinite(P_err) & (P_err > 0)
    order = np.argsort(t[m], kind="stable")
    tt, PP = t[m][order], P[m][order]
    if P_err is not None:
        sig = P_err[m][order] / PP
    if tt.size < 3:
        raise ConfigError(
            f"fewer than 3 usable points (P > 0{', P_err > 0' if P_err is not None else ''}) in window {window}"
        )
    return tt, PP, sig, (lo, hi)


def mean_kappa_stat_err(t, P, P_err, windows) -> float:
    """mean_kappa_stat_err(t, P, P_err, windows) -> σ (1/time) of the mean of the κ fits over ``windows``.

    Statistical standard error of (1/W) Σ_w κ_w, κ_w the weighted least-squares
    slopes of :func:`fit_exponential` on each window (same point selection and
    weights).  The mean is one linear functional of log P; its variance is
    evaluated under the independent-increment covariance of Kaplan–Meier
    log-survival estimates (module docstring), so the overlap of the windows
    (they share data) is accounted for exactly.

    Examples
    --------
    Exponential lifetimes (κ = 0.1): the mean of the fits on two overlapping windows is hardly better determined than
    the fit on their union, because the windows share their data.

    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 20000)
    >>> c = survival_curve(np.minimum(t, 60.0), t < 60.0, t_grid=np.linspace(0.0, 60.0, 61))
    >>> two = mean_kappa_stat_err(c.t, c.P, c.P_err, [(5.0, 30.0), (10.0, 40.0)])
    >>> one = fit_exponential(c.t, c.P, (5.0, 40.0), c.P_err).kappa_err
    >>> round(two, 4), round(one, 4)
    (0.0011, 0.001)
    """
    t = check.floats(t, "t")
    P = check.floats(P, "P", size=t.size, of="t")
    E = check.floats(P_err, "P_err", size=t.size, of="t")
    if isinstance(windows, (str, bytes, dict)) or not hasattr(windows, "__len__") or len(windows) == 0:
        raise ConfigError(f"windows must be a non-empty list of (lo, hi) pairs, got {windows!r}")
    windows = [check.interval(w, "windows[i]") for w in windows]
    order = np.argsort(t, kind="stable")
    t, P, E = t[order], P[order], E[order]
    valid = np.isfinite(t) & np.isfinite(P) & (P > 0) & np.isfinite(E) & (E > 0)
    tv, sv = t[valid], E[valid] / P[valid]
    total = np.zeros(tv.size)
    for lo, hi in windows:
        m = (tv >= lo) & (tv <= hi)
        if np.count_nonzero(m) < 3:
            raise ConfigError(f"fewer than 3 usable points in window {(lo, hi)}")
        X = np.column_stack([tv[m], np.ones(np.count_nonzero(m))])
        total[m] += least_squares_operator(X, 1.0 / sv[m] ** 2)[0][0]
    total /= len(windows)
    return float(np.sqrt(_independent_increment_cov(total[None, :], sv**2)[0, 0]))


@dataclass(frozen=True)
class ExponentialFit(WithErrors):
    """Result of :func:`fit_exponential`: log P = log f0 − κ t on ``window``.

    kappa, kappa_err      escape rate κ and its 1σ error (1/time); the error
                          accounts for the correlation of KM points when
                          P_err was given (see module docstring)
    kappa_err_naive       diagonal-weight (or OLS) formal error
    f0, f0_err            prefactor of Eq. (eqn:kappa_hyperbolic) (dimensionless)
    window                (t_lo, t_hi) requested (time units)
    n_points              grid points used; rms_log_residual  rms of log-P residuals
    weighted              True if weighted by 1/σ²(log P)
    """

    method = "least squares of log P"
    n_field = "n_points"

    kappa: float
    kappa_err: float
    kappa_err_naive: float
    f0: float
    f0_err: float
    window: tuple
    n_points: int
    rms_log_residual: float
    weighted: bool

    def predict(self, t):
        """predict(t) -> f0 exp(−κ t)."""
        return self.f0 * np.exp(-self.kappa * np.asarray(t, dtype=float))


def fit_exponential(t, P, window, P_err=None) -> ExponentialFit:
    """fit_exponential(t, P, window, P_err=None) -> ExponentialFit(kappa, kappa_err, f0, window, ...).

    Least squares of log P on t over ``window`` = (t_lo, t_hi) (time units,
    inclusive), i.e. the exponential regime of Eq. (eqn:kappa_hyperbolic)
    P = f0 e^{−κ t}.  Points with P = 0 or non-finite values are excluded.

    With ``P_err`` (e.g. the Greenwood errors of :func:`survival_curve`) the fit
    is weighted by 1/σ², σ = P_err/P (points with P_err = 0 dropped), and
    ``kappa_err`` is the standard error of that estimator under the
    independent-increment covariance of log KM (see module docstring).  Without
    ``P_err`` it is ordinary least squares and ``kappa_err`` is the formal
    residual-scaled error (which ignores correlations: an underestimate).

    Examples
    --------
    Exponential lifetimes of rate κ = 0.1, censored at t = 60: the fit gives κ near 0.1 and f0 near 1.

    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 20000)
    >>> c = survival_curve(np.minimum(t, 60.0), t < 60.0, t_grid=np.linspace(0.0, 60.0, 61))
    >>> f = fit_exponential(c.t, c.P, (5.0, 40.0), c.P_err)
    >>> round(f.kappa, 4), round(f.kappa_err, 4), round(f.f0, 2), f.n_points
    (0.1003, 0.001, 0.99, 36)
    >>> f.kappa_err > 2 * f.kappa_err_naive      # the correlated Kaplan–Meier points carry less than they seem to
    True
    """
    tt, PP, sig, win = _prepare(t, P, P_err, window, log_t=False)
    beta, alpha, cov, cov_n, n, rms = _fit_log_linear(tt, np.log(PP), sig)
    f0 = math.exp(alpha)
    return ExponentialFit(
        kappa=-beta,
        kappa_err=float(np.sqrt(cov[0, 0])),
        kappa_err_naive=float(np.sqrt(cov_n[0, 0])),
        f0=f0,
        f0_err=f0 * float(np.sqrt(cov[1, 1])),
        window=win,
        n_points=n,
        rms_log_residual=rms,
        weighted=sig is not None,
    )


@dataclass(frozen=True)
class PowerLawFit(WithErrors):
    """Result of :func:`fit_power_law_tail`: log P = log f* − z log t on ``window``.

    z, z_err              power-law exponent of Eq. (eqn:kappa_nonhyperbolic) and
                          its 1σ error (correlation-aware when P_err was given)
    z_err_naive           diagonal-weight (or OLS) formal error
    f_star, f_star_err    prefactor f* (units time^z)
    window, n_points, rms_log_residual, weighted   as in :class:`ExponentialFit`

    Diagnostics filled by :func:`detect_power_law_tail` (NaN otherwise):
    z_mle, z_mle_err      Poisson-MLE exponent of the hazard z/t on the window
    hazard_exponent       MLE β of a hazard ∝ t^{−β} on the window (1: power law, 0: exponential)
    delta_aic_split       AIC gain of "exponential then power law" over one exponential on [τ0, end]
    delta_aic_tail        AIC gain of a power law over an exponential on the tail window
    """

    method = "least squares of log P against log t"
    n_field = "n_points"

    z: float
    z_err: float
    z_err_naive: float
    f_star: float
    f_star_err: float
    window: tuple
    n_points: int
    rms_log_residual: float
    weighted: bool
    z_mle: float = math.nan
    z_mle_err: float = math.nan
    hazard_exponent: float = math.nan
    delta_aic_split: float = math.nan
    delta_aic_tail: float = math.nan

    def predict(self, t):
        """predict(t) -> f* t^{−z}."""
        return self.f_star * np.asarray(t, dtype=float) ** (-self.z)


def fit_power_law_tail(t, P, window, P_err=None) -> PowerLawFit:
    """fit_power_law_tail(t, P, window, P_err=None) -> PowerLawFit(z, z_err, f_star, window, ...).

    Least squares of log P on log t over ``window`` (time units, t > 0), the
    algebraic regime P ≈ f* t^{−z} of Eq. (eqn:kappa_nonhyperbolic).  Weighting
    and errors as in :func:`fit_exponential`.

    Examples
    --------
    A Pareto sample, P(t) = t^{−1.5} for t ≥ 1: z and f* agree with 1.5 and 1 within their errors.

    >>> rng = np.random.default_rng(0)
    >>> t = rng.random(20000) ** (-1 / 1.5)
    >>> c = survival_curve(t, np.ones(t.size, bool), t_grid=np.geomspace(1.0, 100.0, 41))
    >>> f = fit_power_law_tail(c.t, c.P, (2.0, 50.0), c.P_err)
    >>> round(f.z, 2), round(f.z_err, 2), round(f.f_star, 2), round(f.f_star_err, 2)
    (1.49, 0.02, 0.98, 0.03)
    """
    tt, PP, sig, win = _prepare(t, P, P_err, window, log_t=True)
    beta, alpha, cov, cov_n, n, rms = _fit_log_linear(np.log(tt), np.log(PP), sig)
    f_star = math.exp(alpha)
    return PowerLawFit(
        z=-beta,
        z_err=float(np.sqrt(cov[0, 0])),
        z_err_naive=float(np.sqrt(cov_n[0, 0])),
        f_star=f_star,
        f_star_err=f_star * float(np.sqrt(cov[1, 1])),
        window=win,
        n_points=n,
        rms_log_residual=rms,
        weighted=sig is not None,
    )


def crossover_time(t, P, exp_fit, pow_fit) -> float:
    """crossover_time(t, P, exp_fit, pow_fit) -> tau_star (time units; NaN if the laws never cross).

    τ* of Eq. (eqn:kappa_nonhyperbolic): the time where the fitted exponential
    f0 e^{−κt} and the fitted power law f* t^{−z} intersect.  With
    g(τ) = log f0 − κτ − log f* + z log τ (concave for z > 0, maximal at τ = z/κ)
    there are in general two intersections; τ* is the *last* one, where g
    changes sign from + to − and the power law dominates for all later times
    ``t``/``P`` (the data both fits were
    made on) only set the search scale and trigger a warning when τ* falls
    outside the data's time range.

    Examples
    --------
    P = e^{−t/2} up to t = 10, then 10 e^{−5}/t: the two laws meet at t = 10 (and the power law dominates after).

    >>> t = np.arange(1.0, 21.0)
    >>> P = np.where(t < 10, np.exp(-0.5 * t), 10 * np.exp(-5.0) / t)
    >>> e, p = fit_exponential(t, P, (1.0, 9.0)), fit_power_law_tail(t, P, (11.0, 20.0))
    >>> round(e.kappa, 6), round(p.z, 6), round(crossover_time(t, P, e, p), 6)
    (0.5, 1.0, 10.0)
    """
    t = check.floats(t, "t")
    check.floats(P, "P", size=t.size, of="t")
    check.instance(exp_fit, "exp_fit", ExponentialFit)
    check.instance(pow_fit, "pow_fit", PowerLawFit)
    kappa, z = float(exp_fit.kappa), float(pow_fit.z)
    lf0, lfs = math.log(exp_fit.f0), math.log(pow_fit.f_star)

    def g(tau):
        return lf0 - kappa * tau - lfs + z * np.log(tau)

    tpos = t[np.isfinite(t) & (t > 0)]
    scale = float(tpos.max()) if tpos.size else 1.0
    grid = np.geomspace(scale * 1e-6, scale * 1e4, 4001)
    gv = g(grid)
    down = np.flatnonzero((gv[:-1] > 0) & (gv[1:] <= 0))
    if down.size == 0:
        return math.nan
    k = down[-1]
    tau = float(optimize.brentq(g, grid[k], grid[k + 1], xtol=1e-12 * grid[k + 1], rtol=1e-12))
    if tpos.size and not (tpos.min() <= tau <= tpos.max()):
        warnings.warn(
            f"crossover time {tau:.4g} lies outside the data range [{tpos.min():.4g}, {tpos.max():.4g}]", stacklevel=2
        )
    return tau


# ---------------------------------------------------------------------------
# power-law tail detection (Poisson likelihood of the binned hazard)
# ---------------------------------------------------------------------------
def _n_total_from_errors(P, P_err):
    """Ensemble size from binomial errors, N ≈ P(1−P)/P_err², where 0.05 < P < 0.95."""
    if P_err is None:
        return None
    P = np.asarray(P, dtype=float)
    E = np.asarray(P_err, dtype=float)
    m = np.isfinite(P) & np.isfinite(E) & (E > 0) & (P > 0.05) & (P < 0.95)
    if not m.any():
        return None
    return float(np.median(P[m] * (1 - P[m]) / E[m] ** 2))


def _resolve_n_total(P, P_err, n_total):
    if n_total is not None:
        return float(n_total)
    n = _n_total_from_errors(P, P_err)
    if n is None:
        raise ConfigError("n_total (the ensemble size N) is required when P_err cannot provide it")
    return n


def _floor_time(t, P, n_total, min_survivors):
    """Last grid time with finite P and N·P ≥ min_survivors (the counting-statistics floor)."""
    ok = np.isfinite(P) & (P * n_total >= min_survivors)
    if not ok.any():
        return None
    return float(t[np.flatnonzero(ok)[-1]])


def _step_eval(t, P, x):
    """Right-continuous step function (t, P) (t increasing) evaluated at x ≥ t[0]."""
    idx = np.searchsorted(t, x, side="right") - 1
    return P[np.clip(idx, 0, None)]


def _segment_ll(d, expo, logH):
    """Poisson log-likelihood (up to model-independent terms) of one-parameter hazards, maximised.

    For bins with events d, exposure-weighted cumulative-hazard shape ``expo``
    (Σ n_k H_k per unit rate) and Σ d_k log H_k term ``logH``:
        LL = logH + D log(D / X) − D.
    Works on cumulative arrays (broadcasts).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        return logH + xlogy(d, d) - xlogy(d, expo) - d


def detect_power_law_tail(
    t,
    P,
    tau0,
    P_err=None,
    *,
    n_total=None,
    min_survivors: float = 100.0,
    min_span: float = 2.0,
    min_delta_aic: float = 10.0,
    min_hazard_exponent: float = 0.5,
    min_events: float = 50.0,
    bin_width=None,
    min_width: float = 2.0 * math.pi,
):
    """detect_power_law_tail(t, P, tau0, P_err=None, *, n_total=None, ...) -> PowerLawFit or None.

    Decides, from the data after ``tau0`` (time units), whether P(t) ends in an
    algebraic tail f* t^{−z} (Eq. (eqn:kappa_nonhyperbolic)) or stays
    exponential (Eq. (eqn:kappa_hyperbolic)); returns the tail's
    :class:`PowerLawFit` (with diagnostics) or None.

    Rule.  Only times in [τ0, t_floor] are used, t_floor being the last time
    with at least ``min_survivors`` survivors (N·P ≥ min_survivors; N =
    ``n_total``, or estimated from binomial ``P_err``).  P is read at bin
    edges τ0, τ0 + Δ, τ0 + 2Δ, … with Δ = ``bin_width`` (default
    max(``min_width`` = 2π, 1/κ̂), κ̂ the exponential MLE on [τ0, t_floor]), so
    that escape modulated at the orbital period averages out.  The numbers at
    risk n_k = N P(t_k) and of leaving orbits d_k = N (P(t_k) − P(t_{k+1}))
    give a Poisson likelihood of the hazard h(t) in which the normalisations
    f0, f* drop out:

    1. *Change point*: the model "h = κ on [τ0, τc), h = z/t on [τc, t_floor]"
       (closed-form MLEs for every τc on the bin edges) must beat a single
       exponential (h = κ) on [τ0, t_floor] by ΔAIC ≥ ``min_delta_aic``
       (2 extra parameters: z, τc).  τc is the maximum-likelihood change point
       among those leaving ≥ ``min_events`` events on each side and a tail
       spanning t_floor/τc ≥ ``min_span``.
    2. *The tail is algebraic*: on [τc, t_floor] the power law must beat an
       exponential by ΔAIC ≥ ``min_delta_aic``, and the MLE exponent β of a
       hazard ∝ t^{−β} must be ≥ ``min_hazard_exponent`` (β = 1 for a power
       law, 0 for an exponential) — this rejects drifts or modulations of an
       exponential's rate that a huge sample would otherwise flag.

    If both hold, τc is refined on the full grid within one bin of the coarse
    change point (same split likelihood), and the tail is fitted by least
    squares of log P on log t over [τc, t_floor] on the full grid (:func:`fit_power_law_tail`, weighted by
    ``P_err`` if given), with the likelihood diagnostics attached.  The counts
    assume censoring only at the end (N·P = number at risk).  Caveat: within a
    finite range, the crossover between two exponentials with very different
    rates also has β ≈ 1 and is reported as a tail; the answer is a statement
    about the observed range.

    Examples
    --------
    20 % of the orbits sticky, P ∝ 5/t after t = 5; the others leave at rate 0.5: a tail of exponent z ≈ 1 is found.
    A purely exponential sample has none.

    >>> rng = np.random.default_rng(0)
    >>> n, t_max = 100_000, 2000.0
    >>> t = np.where(rng.random(n) < 0.2, 5.0 / rng.random(n), rng.exponential(2.0, n))
    >>> c = survival_curve(np.minimum(t, t_max), t < t_max, t_grid=np.arange(0.0, t_max, 1.0))
    >>> tail = detect_power_law_tail(c.t, c.P, 1.0, c.P_err)
    >>> round(tail.z, 2), tail.window
    (0.99, (6.0, 1239.0))
    >>> t = rng.exponential(2.0, n)
    >>> c = survival_curve(t, np.ones(n, bool), t_grid=np.arange(0.0, 30.0, 0.1))
    >>> detect_power_law_tail(c.t, c.P, 1.0, c.P_err) is None
    True
    """
    t = check.floats(t, "t", size=None)
    P = check.floats(P, "P", size=t.size, of="t")
    if not np.isfinite(t).any():
        raise ConfigError("t must hold at least one finite time")
    check.number(tau0, "tau0")
    if P_err is not None:
        check.floats(P_err, "P_err", size=t.size, of="t")
    if n_total is not None:
        check.number(n_total, "n_total", positive=True)
    observed = _tail_range(t, P, tau0, P_err, n_total, min_survivors)
    if observed is None:
        return None
    N, t_floor, tau0, tf, Pf = observed
    edges = _bin_edges(tf, Pf, N, tau0, t_floor, bin_width, min_width)
    if edges is None:
        return None
    bins = _hazard_bins(tf, Pf, N, edges)
    split = _change_point(bins, edges, t_floor, min_events, min_span)
    if split is None:
        return None
    jb, d_aic_split, d_aic_tail = split
    beta_hat = _hazard_exponent(bins, edges, jb)
    if not (d_aic_split >= min_delta_aic and d_aic_tail >= min_delta_aic and beta_hat >= min_hazard_exponent):
        return None
    tau_c, D_tail, z_mle = _refined_change_point(tf, Pf, N, tau0, t_floor, edges, bins, jb)
    fit = fit_power_law_tail(t, P, (tau_c, t_floor), P_err)
    return PowerLawFit(
        **{
            **fit.__dict__,
            "z_mle": float(z_mle),
            "z_mle_err": float(z_mle / math.sqrt(D_tail)),
            "hazard_exponent": beta_hat,
            "delta_aic_split": float(d_aic_split),
            "delta_aic_tail": float(d_aic_tail),
        }
    )


# the steps of detect_power_law_tail (its docstring's rule, step by step)
def _tail_range(t, P, tau0, P_err, n_total, min_survivors):
    """The observed range [τ0, t_floor] (time units): (N, t_floor, τ0, finite t, finite P), or None if empty."""
    N = _resolve_n_total(P, P_err, n_total)
    t_floor = _floor_time(t, P, N, min_survivors)
    tau0 = max(float(tau0), float(t[np.isfinite(t)].min()))
    if t_floor is None or not t_floor > tau0:
        return None
    ok = np.isfinite(t) & np.isfinite(P)
    return N, t_floor, tau0, t[ok], P[ok]


def _bin_edges(tf, Pf, N, tau0, t_floor, bin_width, min_width):
    """Bin edges τ0, τ0 + Δ, …, t_floor (time units), Δ = bin_width or max(min_width, 1/κ̂); None if < 4 edges.

    κ̂ = D/X is the exponential MLE on [τ0, t_floor] (D orbits leaving over the exposure X).
    """
    m = (tf >= tau0) & (tf <= t_floor)
    if np.count_nonzero(m) < 3:
        return None
    tt, PP = tf[m], Pf[m]
    D_all = N * (PP[0] - PP[-1])
    X_all = float(np.sum(N * PP[:-1] * np.diff(tt)))
    if D_all <= 0 or X_all <= 0:
        return None
    dw = float(bin_width) if bin_width is not None else max(min_width, X_all / D_all)
    edges = np.arange(tau0, t_floor, dw)
    edges = np.append(edges, t_floor) if t_floor - edges[-1] > 0.5 * dw else np.append(edges[:-1], t_floor)
    edges = edges[edges > 0]
    if edges.size < 4:
        return None
    return edges


def _cum0(a):
    """Cumulative sum with a leading 0: entry j is the sum over the first j bins."""
    return np.concatenate([[0.0], np.cumsum(a)])


class _HazardBins(NamedTuple):
    """Counts of a survival curve read at bin edges, per bin and cumulated from the first edge (leading 0).

    n, d: orbits at risk and leaving per bin; D, Xe, Xp, Le, Lp: cumulative d, n Δt (time), n Δlog t,
    d log Δt and d log Δlog t (the sufficient statistics of the hazards h = κ and h = z/t).
    """

    n: np.ndarray
    d: np.ndarray
    D: np.ndarray
    Xe: np.ndarray
    Xp: np.ndarray
    Le: np.ndarray
    Lp: np.ndarray

    @property
    def K(self) -> int:
        """Number of bins."""
        return self.d.size


def _hazard_bins(tf, Pf, N, edges) -> _HazardBins:
    """Numbers at risk n_k = N P(t_k) and leaving d_k = N (P(t_k) − P(t_{k+1})) between ``edges`` (time units)."""
    Pe = _step_eval(tf, Pf, edges)
    n = N * Pe[:-1]
    d = np.clip(N * (Pe[:-1] - Pe[1:]), 0.0, None)
    dt = np.diff(edges)
    dlt = np.diff(np.log(edges))
    return _HazardBins(n, d, _cum0(d), _cum0(n * dt), _cum0(n * dlt), _cum0(xlogy(d, dt)), _cum0(xlogy(d, dlt)))


def _exp_ll(bins: _HazardBins, j):
    """Maximised Poisson log-likelihood of a constant hazard h = κ on the first j bins."""
    return _segment_ll(bins.D[j], bins.Xe[j], bins.Le[j])


def _tail_ll(bins: _HazardBins, j, power: bool):
    """Maximised Poisson log-likelihood on the bins from j on of h = z/t (``power``) or of h = κ."""
    K = bins.K
    X, L = (bins.Xp, bins.Lp) if power else (bins.Xe, bins.Le)
    return _segment_ll(bins.D[K] - bins.D[j], X[K] - X[j], L[K] - L[j])


def _change_point(bins: _HazardBins, edges, t_floor, min_events, min_span):
    """Rule step 1, the change point h = κ → h = z/t: (bin index j_c, ΔAIC split vs exponential, ΔAIC tail).

    j_c maximises the split likelihood among the admissible edges (≥ min_events events on each side, a tail
    spanning t_floor/τc ≥ min_span); the tail ΔAIC compares power law and exponential on [τc, t_floor].
    None if no edge is admissible.
    """
    D, K = bins.D, bins.K
    ll_exp_all = _exp_ll(bins, K)
    j = np.arange(1, K)
    head = _exp_ll(bins, j)
    tail_pow = _tail_ll(bins, j, power=True)
    tail_exp = _tail_ll(bins, j, power=False)
    admissible = (D[j] >= min_events) & (D[K] - D[j] >= min_events) & (t_floor / edges[j] >= min_span)
    if not admissible.any():
        return None
    ll_split = np.where(admissible, head + tail_pow, -np.inf)
    jb = int(j[np.argmax(ll_split)])
    d_aic_split = 2.0 * (float(np.max(ll_split)) - ll_exp_all) - 2.0 * 2
    d_aic_tail = 2.0 * float(tail_pow[jb - 1] - tail_exp[jb - 1])
    return jb, d_aic_split, d_aic_tail


def _hazard_exponent(bins: _HazardBins, edges, jb):
    """Rule step 2, the MLE exponent β (dimensionless) of a hazard ∝ t^{−β} on the bins from jb on.

    Exact bin integrals of t^{−β}, β by profile likelihood in [−3, 5]: 1 for a power law, 0 for an exponential.
    """
    dk, nk = bins.d[jb:], bins.n[jb:]
    lo, hi = edges[jb:-1], edges[jb + 1 :]

    def neg_ll(beta):
        if abs(1.0 - beta) < 1e-8:
            H = np.log(hi / lo)
        else:
            H = (hi ** (1.0 - beta) - lo ** (1.0 - beta)) / (1.0 - beta)
        return -float(_segment_ll(dk.sum(), (nk * H).sum(), xlogy(dk, H).sum()))

    return float(optimize.minimize_scalar(neg_ll, bounds=(-3.0, 5.0), method="bounded").x)


def _refined_change_point(tf, Pf, N, tau0, t_floor, edges, coarse: _HazardBins, jb):
    """τc refined on the full grid within one bin of the coarse change point: (τc (time), tail events, z MLE)."""
    fe = tf[(tf >= tau0) & (tf <= t_floor) & (tf > 0)]
    if fe[-1] < t_floor:
        fe = np.append(fe, t_floor)
    fine = _hazard_bins(tf, Pf, N, fe)
    K, Kf = coarse.K, fine.K
    jf = np.flatnonzero((fe >= edges[jb - 1]) & (fe <= edges[min(jb + 1, K)]))
    jf = jf[(jf >= 1) & (jf < Kf)]
    if jf.size:
        llf = _exp_ll(fine, jf) + _tail_ll(fine, jf, power=True)
        jr = int(jf[np.argmax(llf)])
        D_tail = fine.D[Kf] - fine.D[jr]
        return float(fe[jr]), D_tail, D_tail / (fine.Xp[Kf] - fine.Xp[jr])
    D_tail = coarse.D[K] - coarse.D[jb]
    return float(edges[jb]), D_tail, D_tail / (coarse.Xp[K] - coarse.Xp[jb])
