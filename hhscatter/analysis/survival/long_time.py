"""Long-time escape: a plateau plus an exponential, fitted on the lifetimes with censoring, and the hazard.

Beyond a window fit of log P(t) (Eq. (eqn:kappa_hyperbolic)): a population with orbits that
never leave (KAM tori) or leave very late (stickiness) has a survival probability that flattens, and a window fit
of log P then returns the plateau's slope, not a rate. Here, from a time t0 on, the orbits still inside at t0
are described by

    P(t | t0) = q + (1 − q) e^{−κ (t − t0)},      t ≥ t0,

q the fraction of them that never escapes (P∞ = q·P(t0) of all orbits) and κ the rate of the others (κ_tail).
:func:`fit_plateau_exponential` fits (q, κ) by maximum likelihood on the individual lifetimes: an escape at t
contributes the density (1 − q) κ e^{−κ(t − t0)}, an orbit still inside at its censoring time c the survival
P(c | t0). Censored orbits enter the likelihood as what they are, so the rate is not conditioned on escaping
before t_max (the bias of fitting only the escaping orbits, whose hazard rises towards t_max). Errors from the
inverse of the observed information (numerical Hessian of the log-likelihood at the optimum); P∞ = q·P(t0)
carries both errors, q's and the binomial (Greenwood) error of P(t0): σ(P∞)² = (P(t0) σ_q)² + (q σ_P(t0))² (q is
fitted on the orbits inside at t0, given their number, so the two are independent). The goodness of fit is
Pearson's χ² of the escapes in ``n_bins`` time bins of equal expected counts plus the orbits still inside,
against the fitted model, with adjacent cells pooled until each expects at least 5 orbits (the tail cell joins
its neighbour: :func:`hhscatter.analysis.stats.goodness.pooled_pearson`) and dof = pooled cells − 1 − number of
fitted parameters; with no degree of freedom left the test says "too few orbits" (``too_few``, p NaN). Valid
when every orbit is censored at one t_max (the runs here: γ = 0). With ``plateau=False``, q = 0 (a single
exponential from t0).

:func:`survival_at` gives Kaplan–Meier P(t) and its Greenwood error at chosen times, :func:`hazard_profile` the
censoring-aware hazard per time bin (escapes over orbit-time at risk,
:func:`hhscatter.analysis.survival.effective_rate.binned_hazard`).

Examples
--------
>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> t = np.where(rng.random(20000) < 0.3, np.inf, rng.exponential(1 / 0.01, 20000))   # 30 % never leave
>>> obs = t < 800.0
>>> f = fit_plateau_exponential(np.minimum(t, 800.0), obs, 0.0)
>>> bool(abs(f.p_inf - 0.3) < 4 * f.p_inf_err and abs(f.kappa - 0.01) < 4 * f.kappa_err)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.goodness import TOO_FEW
from hhscatter.errors import ConfigError


@dataclass(frozen=True)
class PlateauFit:
    """Result of :func:`fit_plateau_exponential`.

    Attributes
    ----------
    t0 : float
        Start of the fit (time units).
    n_at_risk : int
        Orbits still inside at t0.
    p_t0 : float
        Fraction of all orbits still inside at t0 (Kaplan–Meier).
    q, q_err : float
        Fraction of the orbits inside at t0 that never escape, and its 1σ error (q = 0 with ``plateau=False``;
        q = 0 with a NaN error where the fitted plateau lies at its boundary 0, as when no orbit after t0 is
        censored: the likelihood then falls with q and its maximum is q = 0).
    p_t0_err : float
        The Greenwood (binomial, without censoring before t0) 1σ error of ``p_t0``.
    p_inf, p_inf_err : float
        P∞ = q·P(t0): the plateau as a fraction of all orbits, its error from q's and P(t0)'s.
    kappa, kappa_err : float
        κ_tail (1/time) of the escaping part, and its 1σ error.
    chi2, dof : float, int
        Pearson χ² of the binned escapes and the orbits still inside against the model (cells pooled to expected
        counts ≥ 5), and its degrees of freedom after pooling; χ² NaN when ``too_few``.
    p_value : float
        P(χ²_dof ≥ chi2); NaN when ``too_few``.
    too_few : bool
        True when the pooled cells leave no degree of freedom: too few orbits for a goodness-of-fit verdict.
    """

    t0: float
    n_at_risk: int
    p_t0: float
    p_t0_err: float
    q: float
    q_err: float
    p_inf: float
    p_inf_err: float
    kappa: float
    kappa_err: float
    chi2: float
    dof: int
    p_value: float
    too_few: bool

    @property
    def chi2_red(self) -> float:
        """χ²/dof (NaN without degrees of freedom)."""
        return self.chi2 / self.dof if self.dof > 0 else math.nan

    def survival(self, t) -> np.ndarray:
        """P(t) of all orbits for t ≥ t0: P(t0)·(q + (1 − q) e^{−κ(t − t0)})."""
        s = np.asarray(t, dtype=float) - self.t0
        return self.p_t0 * (self.q + (1 - self.q) * np.exp(-self.kappa * s))


def _negloglik(q, kappa, s, esc):
    if not (0 <= q < 1 and kappa > 0):
        return math.inf
    ll_esc = np.log1p(-q) + math.log(kappa) - kappa * s[esc]
    with np.errstate(divide="ignore"):
        ll_cen = np.log(q + (1 - q) * np.exp(-kappa * s[~esc]))
    return -float(ll_esc.sum() + ll_cen.sum())


def _hessian(f, x, h):
    n = len(x)
    H = np.empty((n, n))
    for i in range(n):
        for j in range(i, n):
            ei, ej = np.eye(n)[i] * h[i], np.eye(n)[j] * h[j]
            H[i, j] = H[j, i] = (f(x + ei + ej) - f(x + ei - ej) - f(x - ei + ej) + f(x - ei - ej)) / (4 * h[i] * h[j])
    return H


def fit_plateau_exponential(t_end, observed, t0: float, *, plateau: bool = True, n_bins: int = 10) -> PlateauFit:
    """fit_plateau_exponential(t_end, observed, t0, plateau=True, n_bins=10) -> PlateauFit.

    Maximum-likelihood fit of P(t | t0) = q + (1 − q) e^{−κ(t − t0)} on the orbits still inside at ``t0`` (module
    doc): escapes by their density, censored orbits by their survival.

    Parameters
    ----------
    t_end : array (N,), time units
        End time of each orbit (escape, or censoring at t_max).
    observed : bool array (N,)
        True where the orbit escaped at ``t_end``, False where it was still inside (censored).
    t0 : float
        Start of the fit (time units); orbits that left at or before t0 do not enter it.
    plateau : bool
        Fit q (True) or hold q = 0 (a single exponential).
    n_bins : int
        Time bins of the goodness-of-fit χ² (of equal expected escapes under the fit).

    Returns
    -------
    PlateauFit

    Examples
    --------
    30 % of the orbits never leave, the others at rate 0.01; censored at t = 800: P∞ is the share drawn, κ near
    0.01.

    >>> rng = np.random.default_rng(0)
    >>> t = np.where(rng.random(2000) < 0.3, np.inf, rng.exponential(100.0, 2000))
    >>> f = fit_plateau_exponential(np.minimum(t, 800.0), t < 800.0, 0.0)
    >>> round(f.p_inf, 3), round(f.p_inf_err, 3), round(float(np.isinf(t).mean()), 3)
    (0.302, 0.01, 0.302)
    >>> round(f.kappa, 4), round(f.kappa_err, 4)
    (0.0098, 0.0003)
    """
    t = check.numbers(t_end, "t_end", min_size=0, minimum=0.0)
    obs = check.mask(observed, "observed", t.size)
    check.number(t0, "t0", minimum=0.0)
    check.count(n_bins, "n_bins", 1)
    risk = t > t0
    n = int(risk.sum())
    if n < 10 or obs[risk].sum() < 3:
        raise ConfigError(f"too few orbits inside at t0 = {t0:g} ({n}) or escapes after it ({int(obs[risk].sum())})")
    s, esc = t[risk] - t0, obs[risk]
    from scipy.optimize import minimize  # deferred: scipy loads on first use
    from scipy.special import expit  # deferred: scipy loads on first use

    k_start = esc.sum() / max(s.sum(), 1e-300)
    if plateau and esc.all():  # nothing censored: the likelihood falls with q, its maximum is q = 0 exactly
        f0 = fit_plateau_exponential(t, obs, t0, plateau=False, n_bins=n_bins)
        return PlateauFit(**{**f0.__dict__, "q_err": math.nan, "p_inf_err": math.nan})
    if plateau:
        # q by its logit and κ by its logarithm, both mapped without overflow wherever the simplex wanders
        f = lambda v: _negloglik(float(expit(v[0])), math.exp(min(v[1], 700.0)), s, esc)  # noqa: E731
        q_start = min(max(1 - esc.mean(), 1e-3), 1 - 1e-3)
        starts = [(math.log(q_start / (1 - q_start)), math.log(k_start * m)) for m in (1.0, 3.0, 10.0)]
        best = min(
            (
                minimize(f, x0, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-10, "maxiter": 4000})
                for x0 in starts
            ),
            key=lambda r: r.fun,
        )
        q, kappa = float(expit(best.x[0])), math.exp(min(best.x[1], 700.0))
        if q < 1e-6:  # the plateau at its boundary: no plateau; the single exponential, q = 0 without an error
            f0 = fit_plateau_exponential(t, obs, t0, plateau=False, n_bins=n_bins)
            return PlateauFit(**{**f0.__dict__, "q_err": math.nan, "p_inf_err": math.nan})
        g = lambda v: _negloglik(v[0], v[1], s, esc)  # noqa: E731
        x = np.array([q, kappa])
        h = np.array([max(1e-4 * min(q, 1 - q), 1e-9), 1e-4 * kappa])
        try:
            cov = np.linalg.inv(_hessian(g, x, h))
            q_err, k_err = (math.sqrt(v) if v > 0 else math.nan for v in np.diag(cov))
        except np.linalg.LinAlgError:
            q_err = k_err = math.nan
        n_par = 2
    else:
        q, kappa = 0.0, float(k_start)  # the exponential's MLE: escapes over orbit-time at risk
        q_err, k_err = 0.0, kappa / math.sqrt(esc.sum())
        n_par = 1
    g = _pearson(s, esc, q, kappa, n_bins, n_par)
    P0, P0_err = survival_at(t, obs, [t0])
    p_t0, p_t0_err = float(P0[0]), float(P0_err[0])
    return PlateauFit(
        t0=float(t0),
        n_at_risk=n,
        p_t0=p_t0,
        p_t0_err=p_t0_err,
        q=float(q),
        q_err=float(q_err),
        p_inf=float(q * p_t0),
        p_inf_err=float(math.hypot(q_err * p_t0, q * p_t0_err)),
        kappa=float(kappa),
        kappa_err=float(k_err),
        chi2=g.chi2,
        dof=g.dof,
        p_value=g.p_value,
        too_few=g.too_few,
    )


def _km_at(t, obs, t0) -> float:
    from hhscatter.analysis.survival.kaplan_meier import survival_on_grid  # deferred: kept off import time

    return float(survival_on_grid(t, obs, np.array([t0]))[0])


def _pearson(s, esc, q, kappa, n_bins, n_par):
    """Pearson χ² of the escapes in n_bins bins (edges at the fitted model's quantiles of the escape time, up to the
    earliest censoring) and the orbits still inside there, against q + (1 − q) e^{−κs}, cells pooled to expected
    counts ≥ 5 (:func:`~hhscatter.analysis.stats.goodness.pooled_pearson`)."""
    from hhscatter.analysis.stats.goodness import PooledPearson, pooled_pearson  # deferred: scipy on first use

    n = s.size
    c = float(s[~esc].min()) if (~esc).any() else float(s.max())
    S = lambda x: q + (1 - q) * np.exp(-kappa * x)  # noqa: E731
    p_esc = 1 - S(c)
    if p_esc <= 0:
        return PooledPearson(math.nan, 0, math.nan, 0, True)
    levels = 1 - np.linspace(0, p_esc, n_bins + 1)[1:-1]  # S at the inner edges
    inner = -np.log((levels - q) / (1 - q)) / kappa
    edges = np.concatenate([[0.0], inner, [c]])
    obs_counts = np.histogram(s[esc & (s <= c)], bins=edges)[0].astype(float)
    exp_counts = n * (S(edges[:-1]) - S(edges[1:]))
    inside_obs, inside_exp = float((s > c).sum() + (~esc & (s <= c)).sum()), n * S(c)
    o = np.append(obs_counts, inside_obs)
    e = np.append(exp_counts, inside_exp)
    return pooled_pearson(o, e, n_fitted=n_par)


def survival_at(t_end, observed, times) -> tuple[np.ndarray, np.ndarray]:
    """survival_at(t_end, observed, times) -> (P, P_err): Kaplan–Meier P(t) and its Greenwood error at ``times``.

    >>> P, e = survival_at([1.0, 2.0, 3.0, 4.0], [True, True, False, False], [1.5, 3.5])
    >>> P.round(12).tolist()  # the product (3/4)(2/3): 0.5 to rounding
    [0.75, 0.5]
    """
    from hhscatter.analysis.survival.kaplan_meier import survival_curve  # deferred: kept off import time

    t = check.numbers(t_end, "t_end", min_size=0)
    o = check.mask(observed, "observed", t.size)
    check.numbers(times, "times")
    c = survival_curve(t, o, t_grid=np.asarray(times, float))
    return np.asarray(c.P, float), np.asarray(c.P_err, float)


def hazard_profile(t_end, escaped, edges):
    """hazard_profile(t_end, escaped, edges) -> DataFrame[t_lo, t_hi, t_mid, events, exposure, hazard, hazard_err]:
    the censoring-aware hazard per bin (escapes over orbit-time at risk, 1/time; Poisson error).

    >>> h = hazard_profile([10.0, 20.0, 100.0], [True, True, False], [0.0, 50.0, 100.0])
    >>> h["events"].tolist()
    [2.0, 0.0]
    """
    from hhscatter.analysis.survival.effective_rate import binned_hazard  # deferred: pandas loads on first use

    return binned_hazard(t_end, escaped, edges)  # its arguments checked there, before any work


@dataclass(frozen=True)
class RateStatus:
    """Result of :func:`rate_status`: whether a window κ is the rate of the population.

    Attributes
    ----------
    status : str
        'exponential' (one exponential from τ0 on, with the orbits still inside at t_max a negligible share),
        'trapped' (a legacy value, kept because tables and records written before read it: the censored orbits,
        still inside at t_max, are more than ``max_bias`` of P at the window end: the window measures the
        plateau), 'non-exponential' (one exponential from τ0 is rejected, p < ``p_reject``),
        'too few orbits' (one exponential from τ0 can be neither accepted nor rejected: the pooled χ² has no
        degree of freedom, :data:`hhscatter.analysis.stats.goodness.TOO_FEW`, or too few orbits to fit it), or
        'empty' (no orbit was still inside after τ0: every one left before the window, which holds no rate).
    censored_fraction : float
        Orbits still inside at the end (censored), of all (``trapped_fraction``, its name before, reads it too).
    p_inf, p_inf_err, kappa_inf, kappa_inf_err : float
        The plateau-plus-exponential fit from τ0 (:func:`fit_plateau_exponential`); NaN where it fails.
    p_value : float
        Of one exponential from τ0 (Pearson χ², :class:`PlateauFit`); NaN where undefined.
    note : str
        Empty for 'exponential'; otherwise what the κ is and what to read instead.
    """

    status: str
    censored_fraction: float
    p_inf: float
    p_inf_err: float
    kappa_inf: float
    kappa_inf_err: float
    p_value: float
    note: str

    @property
    def trapped_fraction(self) -> float:
        """The name of :attr:`censored_fraction` before the survivors' vocabulary (kept so that callers do not
        break)."""
        return self.censored_fraction


def rate_status(
    t_end, observed, tau0: float, t_stop: float, *, max_bias: float = 0.1, p_reject: float = 1e-3
) -> RateStatus:
    """rate_status(t_end, observed, tau0, t_stop, max_bias=0.1, p_reject=1e-3) -> RateStatus.

    Says whether the κ fitted on [τ0, t_stop] (time units) is the escape rate of the population: 'trapped' (the
    status's legacy value, see the glossary) when the censored orbits, still inside at t_max, are more than ``max_bias`` of P(t_stop)
    (:func:`hhscatter.analysis.survival.kappa_conventions.plateau_check`), 'non-exponential' when one exponential
    from τ0 is rejected (censoring-aware fit, Pearson χ² p < ``p_reject``), 'too few orbits' when that test has
    no verdict (by the pooled χ²'s own rule, :func:`~hhscatter.analysis.stats.goodness.pooled_pearson`: no degree
    of freedom left once every cell expects 5 orbits; or too few orbits after τ0 to fit), 'empty' when no orbit
    was still inside after τ0, else 'exponential'. With no orbit still inside at the end there is no plateau. With a plateau,
    the note gives P∞ and κ_tail of the plateau-plus-exponential fit.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(2)
    >>> t = np.where(rng.random(5000) < 0.5, np.inf, rng.exponential(100.0, 5000))
    >>> rate_status(np.minimum(t, 800.0), t < 800.0, 10.0, 700.0).status
    'trapped'
    >>> t = rng.exponential(10.0, 5000)
    >>> rate_status(np.minimum(t, 800.0), t < 800.0, 1.0, 60.0).status
    'exponential'
    >>> rate_status(t, np.ones(t.size, bool), 1e6, 2e6).status     # every orbit left before τ0
    'empty'
    >>> rate_status(t[:8], np.ones(8, bool), 0.5, 20.0).status     # 8 orbits: no verdict either way
    'too few orbits'
    """
    from hhscatter.analysis.survival.kappa_conventions import plateau_check  # deferred: kept off import time

    t = check.numbers(t_end, "t_end", min_size=0, minimum=0.0)
    obs = check.mask(observed, "observed", t.size)
    check.number(tau0, "tau0", minimum=0.0)
    check.number(t_stop, "t_stop")
    check.number(max_bias, "max_bias", positive=True)
    check.number(p_reject, "p_reject", positive=True)
    nan = math.nan
    f_inf = float((~obs).mean()) if obs.size else math.nan
    if not (t > tau0).any():  # the whole population left before the window: no plateau and no rate
        return RateStatus(
            "empty",
            f_inf,
            nan,
            nan,
            nan,
            nan,
            nan,
            f"no orbit is inside after τ0 = {tau0:.3g} (all {t.size} ended by then): the window holds no escape "
            "and no rate",
        )
    P_end = _km_at(t, obs, t_stop)
    # no orbit still inside at the end: no plateau, whatever P at the window end (0 of 0 is no bias)
    defined, bias, _ = plateau_check(P_end, f_inf, max_bias) if f_inf > 0 else (True, 0.0, "")
    try:
        pf = fit_plateau_exponential(t, obs, tau0)
        plat = (pf.p_inf, pf.p_inf_err, pf.kappa, pf.kappa_err)
    except ValueError:
        plat = (nan, nan, nan, nan)
    try:
        one = fit_plateau_exponential(t, obs, tau0, plateau=False)
        p, too_few, why = one.p_value, one.too_few, f"the pooled χ² has {one.dof} degrees of freedom"
    except ValueError as exc:  # too few orbits after τ0 to fit one exponential at all
        p, too_few, why = nan, True, str(exc)
    if not defined:
        status = "trapped"
        note = (
            f"not a rate of the whole population: {f_inf:.1%} of the orbits are still inside at t_max, "
            f"{bias:.0%} of P at the window end; the window's κ is the plateau's. Plateau-plus-exponential "
            f"from τ0: P∞ = {plat[0]:.3g} ± {plat[1]:.2g}, κ_tail = {plat[2]:.3g} ± {plat[3]:.2g} (escaping part)"
        )
    elif math.isfinite(p) and p < p_reject:
        status = "non-exponential"
        note = (
            f"P(t) is not one exponential from τ0 = {tau0:.3g} (censoring-aware fit rejected, p = {p:.1e}); "
            "κ is an average over a hazard that changes with time"
        )
    elif too_few:
        status = TOO_FEW
        note = (
            f"{TOO_FEW} to say whether P(t) is one exponential from τ0 = {tau0:.3g} ({why}); κ is not shown to be "
            "the population's rate"
        )
    else:
        status, note = "exponential", ""
    return RateStatus(status, f_inf, *plat, p, note)
