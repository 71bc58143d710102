"""The homogeneous survival model of dissipative scattering, Eq. (eqn:surv_prob_model), its fit
and the τ1 it predicts; the sub-ensemble version is :mod:`hhscatter.analysis.dissipative.mixture`.

Homogeneous model
-----------------
All orbits are assumed to share the energy path of Eq. (eqn:energy_exp_decay),
E(t) = E0 e^{−μγt}, and hence the time-dependent escape rate
κ_γ(t) = κ0(E(t)), where κ0(E) is the conservative escape rate as a function of the energy (zero
for E ≤ E_c; e.g. the piecewise law :class:`~hhscatter.analysis.survival.kappa_law.PiecewiseKappa`).  Then, Eq. (eqn:surv_prob_model),

    P_γ(t) = NaN ("irregular")                          t < τ0
           = f_ne + f_e exp(−κ_γ(t) (t − τ0))             τ0 ≤ t ≤ τ2
           = f_ne exp(−g(t, γ) (t − τ2))                  t > τ2
    g(t, γ) = L / (1 + exp(−b (t − τ2)))²,
    f_ne + f_e = P(τ0),   τ2 = ln(E0/E_c)/(μγ)  (Eq. (eq:tau2)).

Caveat, ``hazard`` option.  Taken literally ("paper", the default), the
escape factor exp(−κ_γ(t)(t−τ0)) uses the *instantaneous* rate times the
elapsed time.  Because κ0(E(t)) → 0 as E(t) → E_c, this factor is not
monotone: it returns to 1 as t → τ2, so the literal P(t) rises back to
f_ne + f_e = P(τ0) just before τ2 and then jumps down to f_ne (when τ2 is tied
to μ by Eq. (eq:tau2), E(τ2) = E_c exactly).  A survival function cannot
increase; the physically consistent reading of "exponential decay with a
time-dependent rate", Eq. (eqn:Pt_escape_generic), is the cumulative hazard
exp(−∫_{τ0}^{t} κ0(E(s)) ds), selected with ``hazard="integrated"``.  Both
coincide for constant κ.  Which one describes a measured P(t) is for the
data to decide; the fitting code supports both.

Both fits return :class:`SurvivalFit` with the same goodness-of-fit measures
(χ², dof, χ²/dof, RMS of log residuals, AIC) on the same data selection, so
that :func:`~hhscatter.analysis.dissipative.model_comparison.compare_fits` can tabulate them side by side; the τ1 a fit
predicts is in :mod:`hhscatter.analysis.dissipative.model_comparison`.

Units: time in model units, energies in model units, rates in 1/time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import special

from hhscatter.analysis.dissipative.curve_fit import (
    _fit_stats,
    _FitStats,
    _lsq,
    _p_at,
    _residual_fn,
    _select_points,
    profile_interval,  # noqa: F401 - importable from here too
)
from hhscatter.analysis.dissipative.decay import _energy_path
from hhscatter.analysis.dissipative.transitions import tau2_predicted
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "HAZARDS",
    "HomogeneousProblem",
    "SurvivalFit",
    "SurvivalModelParams",
    "fit_survival_model",
    "profile_interval",
    "settling_rate",
    "survival_model",
    "survival_model_sample",
]

HAZARDS = ("paper", "integrated")


# ---------------------------------------------------------------------------
# building blocks
# ---------------------------------------------------------------------------
def _time_or_inf(v, name: str) -> float:
    """``v`` as a time (time units) that may be +inf (never), not NaN."""
    v = check.real(v, name)
    if v != v:
        raise ConfigError(f"{name} must be a time or inf, got nan")
    return v


def _optional_mapping(d, name: str) -> None:
    if d is not None:
        check.mapping(d, name)


def settling_rate(t, tau2: float, L: float, b: float):
    """settling_rate(t, tau2, L, b) -> g(t) = L / (1 + exp(−b (t − τ2)))² (Eq. (eqn:surv_prob_model), t > τ2 branch).

    Increases monotonically from L/4 at t = τ2 to L; rate in 1/time.

    Examples
    --------
    >>> settling_rate([60.0, 1000.0], 60.0, 0.1, 0.2).tolist()      # L/4 at τ2, L long after
    [0.025, 0.1]
    """
    check.numbers(t, "t", min_size=0)
    for value, name in ((tau2, "tau2"), (L, "L"), (b, "b")):
        check.real(value, name)
    return _settling_rate(t, tau2, L, b)


def _settling_rate(t, tau2, L, b):
    """:func:`settling_rate` without its checks, for the models that evaluate it at every step of a fit."""
    return L * special.expit(b * (np.asarray(t, dtype=float) - tau2)) ** 2


def _escape_exponent(t, kappa_of_E, A, mu, gamma, tau0, hazard, n_int=4001):
    """X(t) for t ≥ τ0 along E(t) = A e^{−μγt}: κ0(E(t))(t−τ0), or ∫_{τ0}^t κ0(E(s))ds with hazard "integrated"."""
    t = np.asarray(t, dtype=float)
    if hazard == "paper":
        return np.asarray(kappa_of_E(_energy_path(t, A, mu, gamma)), dtype=float) * (t - tau0)
    if hazard == "integrated":
        if t.size == 0:
            return t.copy()
        t_hi = float(np.max(t))
        if t_hi <= tau0:
            return np.zeros_like(t)
        s = np.linspace(tau0, t_hi, n_int)
        k = np.asarray(kappa_of_E(_energy_path(s, A, mu, gamma)), dtype=float)
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
        return np.interp(t, s, cum)
    raise ConfigError(f"hazard must be one of {HAZARDS}, got {hazard!r}")


def _component(t, kappa_of_E, A, mu, gamma, tau0, tau2, f_ne, f_e, L, b, hazard):
    """One (sub-)ensemble of Eq. (eqn:surv_prob_model); NaN for t < τ0."""
    t = np.asarray(t, dtype=float)
    out = np.full(t.shape, np.nan)
    mid = (t >= tau0) & (t <= tau2)
    late = (t > tau2) & (t >= tau0)
    if mid.any():
        out[mid] = f_ne + f_e * np.exp(-_escape_exponent(t[mid], kappa_of_E, A, mu, gamma, tau0, hazard))
    if late.any():
        tl = t[late]
        out[late] = f_ne * np.exp(-_settling_rate(tl, tau2, L, b) * (tl - tau2))
    return out


# ---------------------------------------------------------------------------
# homogeneous model
# ---------------------------------------------------------------------------
def _check_model(kappa_of_E, E0, mu, gamma, tau0, tau2, f_ne, f_e, L, b, E_c, hazard) -> None:
    """The checks of the homogeneous model's parameters (a ConfigError naming the first wrong one)."""
    check.function(kappa_of_E, "kappa_of_E")
    for value, name in ((E0, "E0"), (mu, "mu"), (gamma, "gamma"), (f_ne, "f_ne"), (f_e, "f_e"), (L, "L"), (b, "b")):
        check.real(value, name)
    check.number(tau0, "tau0")
    if tau2 is not None:
        check.real(tau2, "tau2")
    check.number(E_c, "E_c", positive=True)
    if hazard not in HAZARDS:
        raise ConfigError(f"hazard must be one of {HAZARDS}, got {hazard!r}")


def survival_model(
    t,
    *,
    kappa_of_E: Callable,
    E0: float,
    mu: float,
    gamma: float,
    tau0: float,
    tau2: float | None = None,
    f_ne: float,
    f_e: float,
    L: float,
    b: float,
    E_c: float,
    hazard: str = "paper",
):
    """survival_model(t, *, kappa_of_E, E0, mu, gamma, tau0, tau2, f_ne, f_e, L, b, E_c, hazard) -> P(t).

    The homogeneous survival model, Eq. (eqn:surv_prob_model), with
    κ_γ(t) = κ0(E(t)) and E(t) = E0 e^{−μγt} (Eq. (eqn:energy_exp_decay)):

        t < τ0        NaN  (the "irregular" initial regime is not modelled)
        τ0 ≤ t ≤ τ2   f_ne + f_e exp(−κ_γ(t)(t − τ0))       [hazard="paper"]
                      f_ne + f_e exp(−∫_{τ0}^t κ_γ ds)      [hazard="integrated"]
        t > τ2        f_ne exp(−g(t)(t − τ2)),  g = L/(1 + e^{−b(t−τ2)})²

    ``kappa_of_E`` is κ0(E) (vectorised callable, e.g. a :class:`~hhscatter.analysis.survival.kappa_law.PiecewiseKappa`);
    ``tau2=None`` uses Eq. (eq:tau2), ln(E0/E_c)/(μγ).  See the module
    docstring for why the literal ("paper") escape factor is non-monotone.
    Returns an array shaped like ``t`` (float if ``t`` is scalar).

    Examples
    --------
    A constant κ0 = 0.05 (1/time): between τ0 and τ2 (here ln(0.3 · 6)/(0.91 · 0.01) ≈ 64.6) the model is
    f_ne + f_e e^{−κ0 (t − τ0)} with either escape factor; before τ0 it is not modelled (NaN).

    >>> kw = dict(kappa_of_E=lambda E: np.full(np.shape(E), 0.05), E0=0.3, mu=0.91, gamma=0.01, tau0=5.0,
    ...           f_ne=0.1, f_e=0.4, L=0.1, b=0.2, E_c=1 / 6)
    >>> t = np.array([2.0, 5.0, 25.0, 60.0])
    >>> P, P_int = survival_model(t, **kw), survival_model(t, **kw, hazard="integrated")
    >>> bool(np.isnan(P[0])), bool(np.allclose(P[1:], 0.1 + 0.4 * np.exp(-0.05 * (t[1:] - 5.0)))), bool(np.allclose(P_int[1:], P[1:]))
    (True, True, True)
    """
    check.numbers(t, "t", min_size=0)
    _check_model(kappa_of_E, E0, mu, gamma, tau0, tau2, f_ne, f_e, L, b, E_c, hazard)
    if tau2 is None:
        tau2 = tau2_predicted(E0, E_c, mu, gamma)
    out = _component(t, kappa_of_E, E0, mu, gamma, tau0, tau2, f_ne, f_e, L, b, hazard)
    return float(out) if np.ndim(t) == 0 else out


def survival_model_sample(t, n_orbits: int, *, seed: int = 0, **model) -> tuple[np.ndarray, np.ndarray]:
    """survival_model_sample(t, n_orbits, *, seed=0, **model) -> (P, P_err): :func:`survival_model` as measured
    on ``n_orbits`` orbits, a curve whose parameters are known (to test a fit).

    At each time of ``t`` (time units) the number of orbits still inside is a binomial draw of ``n_orbits`` trials
    with the model's P(t) (``model``: the keyword arguments of :func:`survival_model`), each time independently of
    the others (the points of a measured survival curve are correlated; these are not). Before τ0, where the model
    is NaN, every orbit is inside (P = 1). ``P_err`` is the binomial 1σ √(P(1 − P)/N) of the drawn P
    (dimensionless, as P). ``seed`` seeds the draws.

    Examples
    --------
    A constant κ0 = 0.05 (1/time) and 10⁶ orbits: 1 before τ0 with no error, then the closed form
    f_ne + f_e e^{−κ0 (t − τ0)} within 5σ of the binomial noise.

    >>> kw = dict(kappa_of_E=lambda E: np.full(np.shape(E), 0.05), E0=0.3, mu=0.91, gamma=0.01, tau0=5.0,
    ...           f_ne=0.1, f_e=0.4, L=0.1, b=0.2, E_c=1 / 6)
    >>> t = np.array([0.0, 5.0, 25.0, 60.0])
    >>> P, P_err = survival_model_sample(t, 10**6, **kw)
    >>> float(P[0]), float(P_err[0]), bool(np.all(np.abs(P[1:] - (0.1 + 0.4 * np.exp(-0.05 * (t[1:] - 5.0)))) < 5 * P_err[1:]))
    (1.0, 0.0, True)
    """
    t = check.numbers(t, "t", min_size=0)
    n = check.count(n_orbits, "n_orbits", 1)
    rng = np.random.default_rng(check.count(seed, "seed", 0))
    P_true = np.nan_to_num(survival_model(t, **model), nan=1.0)
    if not np.all((P_true >= 0) & (P_true <= 1)):
        raise ConfigError("model: its P(t) leaves [0, 1] (f_ne + f_e ≤ 1 and both ≥ 0 are needed)")
    P = rng.binomial(n, P_true) / n
    return P, np.sqrt(P * (1 - P) / n)


@dataclass(frozen=True)
class SurvivalModelParams:
    """All inputs of :func:`survival_model`; calling it evaluates P(t).

    The inputs are checked as :func:`survival_model` checks them, when the parameters are built: a wrong one is
    refused with a ConfigError naming it.

    Examples
    --------
    A constant κ0 = 0.05 (1/time) with τ2 = 30: at τ0 = 5 the model is f_ne + f_e = 0.5.

    >>> params = SurvivalModelParams(lambda E: np.full(np.shape(E), 0.05), E0=0.3, mu=0.91, gamma=0.01, tau0=5.0,
    ...                              tau2=30.0, f_ne=0.1, f_e=0.4, L=0.1, b=0.2, E_c=1 / 6)
    >>> round(float(params(5.0)), 12)
    0.5
    >>> SurvivalModelParams(lambda E: E, E0=0.3, mu=0.91, gamma=0.01, tau0=5.0, tau2=30.0, f_ne=0.1, f_e=0.4,
    ...                     L=0.1, b=0.2, E_c=True)
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: E_c must be a finite number, got True
    """

    kappa_of_E: Callable
    E0: float
    mu: float
    gamma: float
    tau0: float
    tau2: float
    f_ne: float
    f_e: float
    L: float
    b: float
    E_c: float
    hazard: str = "paper"

    def __post_init__(self):
        _check_model(self.kappa_of_E, self.E0, self.mu, self.gamma, self.tau0, self.tau2, self.f_ne, self.f_e,
                     self.L, self.b, self.E_c, self.hazard)  # fmt: skip

    def __call__(self, t):
        return survival_model(
            t,
            kappa_of_E=self.kappa_of_E,
            E0=self.E0,
            mu=self.mu,
            gamma=self.gamma,
            tau0=self.tau0,
            tau2=self.tau2,
            f_ne=self.f_ne,
            f_e=self.f_e,
            L=self.L,
            b=self.b,
            E_c=self.E_c,
            hazard=self.hazard,
        )


@dataclass
class SurvivalFit:
    """Result of :func:`fit_survival_model` / :func:`fit_mixture_model`.

    ``params``     callable model with the best-fit values (P(t) = params(t));
    ``values``     dict of all parameter values (free, fixed and derived);
    ``errors``     dict of 1σ errors (0 for fixed parameters; derived ones
                   propagated from the covariance);
    ``free``       names of the fitted parameters, ``cov`` their covariance;
    ``chi2, dof, chi2_red``  Σ r², n − k, χ²/dof of the normalised residuals r
                   in the fitted ``space`` ("log": (ln P_model − ln P)/(σ_P/P));
    ``rms_log_residual``  √mean (ln P_model − ln P)² over the fitted points;
    ``aic``        χ² + 2k (for comparing models with different k);
    ``t_fit, residuals``  fitted times and normalised residuals.
    """

    params: object
    values: dict
    errors: dict
    free: tuple
    cov: np.ndarray
    chi2: float
    dof: int
    chi2_red: float
    rms_log_residual: float
    aic: float
    n_points: int
    space: str
    t_fit: np.ndarray = field(repr=False)
    residuals: np.ndarray = field(repr=False)
    success: bool = True
    message: str = ""

    def predict(self, t):
        """predict(t) -> P_model(t) with the best-fit parameters."""
        return self.params(t)


# ---------------------------------------------------------------------------
# homogeneous fit
# ---------------------------------------------------------------------------
_HOMOG = ("f_ne", "f_e", "L", "b", "tau2")


def _survival_fit(model, values, errors, free, st: _FitStats, t_fit, residuals, sol, space) -> SurvivalFit:
    return SurvivalFit(
        params=model,
        values=values,
        errors=errors,
        free=tuple(free),
        cov=st.cov,
        chi2=st.chi2,
        dof=st.dof,
        chi2_red=st.chi2_red,
        rms_log_residual=st.rms,
        aic=st.aic,
        n_points=int(t_fit.size),
        space=space,
        t_fit=t_fit,
        residuals=residuals,
        success=bool(sol.success) if sol is not None else True,
        message=str(sol.message) if sol is not None else "no free parameters",
    )


def fit_survival_model(
    t,
    P,
    P_err,
    *,
    kappa_of_E: Callable,
    E0: float,
    mu: float,
    gamma: float,
    tau0: float,
    tau2: float | None = None,
    E_c: float,
    fixed: dict | None = None,
    fit_tau2: bool = False,
    p0: dict | None = None,
    P_tau0: float | None = None,
    constrain_total: bool = True,
    space: str = "log",
    P_min: float = 0.0,
    t_max: float | None = None,
    hazard: str = "paper",
    absolute_sigma: bool = True,
) -> SurvivalFit:
    """fit_survival_model(t, P, P_err, *, kappa_of_E, E0, mu, gamma, tau0, ...) -> SurvivalFit.

    Weighted least-squares fit of Eq. (eqn:surv_prob_model) to a measured
    survival curve P(t) ± P_err (e.g. from
    :func:`hhscatter.analysis.dissipative.transitions.survival_curve`) on τ0 ≤ t ≤ t_max.

    Parameters: f_ne, f_e, L, b and τ2.  The energy path (E0, μ, γ) and κ0(E)
    are inputs (measured elsewhere: :func:`~hhscatter.analysis.dissipative.decay.fit_energy_decay`
    and the conservative escape rate).

    * ``constrain_total`` (default True): f_e = P(τ0) − f_ne, Eq. (eqn:surv_prob_model);
      P(τ0) is ``P_tau0`` (taken as exact) or, if None, log-linearly
      interpolated from the data; its error is then propagated into the
      errors and ``cov`` by re-fitting at P(τ0) + σ (linear sensitivity).
    * τ2 is fixed at ``tau2`` (None: Eq. (eq:tau2)) unless ``fit_tau2``; then
      it is fitted by profiling χ² over τ2 (the model jumps at τ2, so χ² is
      only piecewise smooth there) and its error is the half-width of the
      Δχ² = 1 region (scaled by χ²/dof unless ``absolute_sigma``).
    * ``fixed``: dict name → value holding any of f_ne, f_e, L, b fixed.
    * ``p0``: dict of starting values (defaults are data-driven, with a few
      starts for b).
    * ``space``: "log" (residuals (ln P_model − ln P)/(σ_P/P), default) or
      "linear" ((P_model − P)/σ_P).  Points with P ≤ ``P_min`` are dropped
      (log residuals need counts ≫ 1: use P_min ≈ 20/N).
    * ``absolute_sigma`` (default True): P_err are true standard deviations
      (binomial errors); False rescales the covariance by χ²/dof.

    Error model: points are treated as independent (diagonal weights).  The
    points of one empirical survival curve are positively correlated
    (log P is a cumulative sum of increments), so on a fine time grid the
    χ²/dof and the parameter errors of such a fit are not calibrated (the
    errors are too small); use a coarse grid, or resample orbits (bootstrap
    over the lifetimes table) for honest errors.  With independent
    per-point noise (tests) the errors are calibrated.

    Returns SurvivalFit (params, values, errors, χ²/dof, RMS log residual,
    AIC, ...).

    Examples
    --------
    A curve made by the model itself (f_ne = 0.1, f_e = 0.4, L = 0.1, b = 0.2) with the noise of 10⁵ orbits: the fit
    finds its parameters back within their errors (f_e = P(τ0) − f_ne, τ2 from Eq. (eq:tau2): 64.59).

    >>> from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
    >>> kappa = PiecewiseKappa(E_c=1 / 6, a2=13.63, a1=0.03, slope=1.41, E_switch=0.27)
    >>> kw = dict(kappa_of_E=kappa, E0=0.3, mu=0.91, gamma=0.01, tau0=5.0, E_c=1 / 6)
    >>> t, N = np.arange(0.0, 301.0), 100_000
    >>> P, P_err = survival_model_sample(t, N, **kw, f_ne=0.1, f_e=0.4, L=0.1, b=0.2)      # N orbits, binomial noise
    >>> f = fit_survival_model(t, P, P_err, **kw, P_min=20 / N)
    >>> f.free, {k: round(float(f.values[k]), 3) for k in ("f_ne", "f_e", "L", "b", "tau2")}
    (('f_ne', 'L', 'b'), {'f_ne': 0.099, 'f_e': 0.402, 'L': 0.1, 'b': 0.199, 'tau2': 64.592})
    >>> {k: round(float(f.errors[k]), 4) for k in ("f_ne", "L", "b")}
    {'f_ne': 0.0006, 'L': 0.0003, 'b': 0.0047}
    """
    check.function(kappa_of_E, "kappa_of_E")
    check.number(E0, "E0", positive=True)
    check.number(mu, "mu")
    check.number(gamma, "gamma", minimum=0.0)
    if tau2 is not None:
        _time_or_inf(tau2, "tau2")
    check.number(E_c, "E_c", positive=True)
    _optional_mapping(fixed, "fixed")
    _optional_mapping(p0, "p0")
    if space not in ("log", "linear"):
        raise ConfigError(f"space must be 'log' or 'linear', got {space!r}")
    fixed = _checked_fixed(fixed, hazard)
    P_tau0, P_tau0_err, tf, Pf, sf = _fit_data(t, P, P_err, tau0, P_tau0, t_max, P_min)
    tau2_eq, fit_tau2 = _settling_time(E0, E_c, mu, gamma, tau2, fixed, fit_tau2)
    free = tuple(n for n in ("f_ne", "f_e", "L", "b") if n not in fixed and not (n == "f_e" and constrain_total))
    fne0, fe0, L0, b_starts = _homogeneous_start(tf, Pf, tau2_eq, P_tau0, fixed, p0)
    prob = HomogeneousProblem(
        tf,
        Pf,
        sf,
        kappa_of_E,
        E0,
        mu,
        gamma,
        tau0,
        E_c,
        hazard,
        space,
        free,
        fixed,
        {"f_ne": fne0, "f_e": fe0, "L": L0},
        b_starts,
        constrain_total,
        P_tau0,
    )
    tau2_fit, tau2_err, sol, res = _fit_settling_time(prob, tau2_eq, fit_tau2, absolute_sigma)
    return _homogeneous_result(prob, sol, res, tau2_fit, tau2_err, fit_tau2, P_tau0_err, absolute_sigma)


# the steps of fit_survival_model (and, for the data, of fit_mixture_model)
def _checked_fixed(fixed, hazard) -> dict:
    """A copy of ``fixed`` (name → value) after checking its names and the ``hazard`` option."""
    fixed = dict(fixed or {})
    unknown = set(fixed) - set(_HOMOG)
    if unknown:
        raise ConfigError(f"unknown parameters in fixed: {sorted(unknown)}")
    if hazard not in HAZARDS:
        raise ConfigError(f"hazard must be one of {HAZARDS}, got {hazard!r}")
    return fixed


def _fit_data(t, P, P_err, tau0, P_tau0, t_max, P_min):
    """P(τ0) and its error (0 when given, else interpolated), and the points fitted: (P_tau0, σ, tf, Pf, sf).

    The points are those with τ0 ≤ t ≤ t_max (time units), P > P_min and a positive error; at least 3.
    """
    size = check.floats(t, "t").size
    check.floats(P, "P", size=size, of="time t")
    check.floats(P_err, "P_err", size=size, of="time t")
    check.number(tau0, "tau0")
    if P_tau0 is not None:
        check.number(P_tau0, "P_tau0", minimum=0.0)
    if t_max is not None:
        check.real(t_max, "t_max")
    check.number(P_min, "P_min")
    t_all = np.asarray(t, dtype=float)
    if P_tau0 is None:
        P_tau0, P_tau0_err = _p_at(t_all, P, P_err, tau0)
    else:
        P_tau0_err = 0.0
    tf, Pf, sf = _select_points(t, P, P_err, tau0, t_max, P_min)
    if tf.size < 3:
        raise ConfigError("fewer than 3 data points selected")
    return P_tau0, P_tau0_err, tf, Pf, sf


def _settling_time(E0, E_c, mu, gamma, tau2, fixed, fit_tau2):
    """τ2 (time units) to hold or start from: ``fixed["tau2"]`` (popped; then not fitted), ``tau2`` or Eq. (eq:tau2).

    Returns (τ2, whether τ2 is fitted).
    """
    tau2_eq = tau2_predicted(E0, E_c, mu, gamma) if tau2 is None else float(tau2)
    if "tau2" in fixed:
        tau2_eq, fit_tau2 = float(fixed.pop("tau2")), False
    return tau2_eq, fit_tau2


def _fit_settling_time(prob: HomogeneousProblem, tau2_eq, fit_tau2, absolute_sigma):
    """The fit with τ2 profiled (``fit_tau2``) or held at ``tau2_eq``: (τ2, σ_τ2 (time), solution, residual fn)."""
    tau2_err = 0.0
    if fit_tau2:
        tau2_fit, tau2_err, sol, _, res = prob.fit_tau2(absolute_sigma)
    else:
        tau2_fit = tau2_eq
        sol, _, res = prob.fit_at(tau2_fit)
    return tau2_fit, tau2_err, sol, res


def _homogeneous_result(
    prob: HomogeneousProblem, sol, res, tau2_fit, tau2_err, fit_tau2, P_tau0_err, absolute_sigma
) -> SurvivalFit:
    """The SurvivalFit of a solution: goodness of fit, errors with P(τ0)'s error propagated through the constraint."""
    free, tf, P_tau0 = prob.free, prob.tf, prob.P_tau0
    k = len(free) + (1 if fit_tau2 else 0)
    theta = sol.x if sol is not None else np.array([])
    v = prob.values(theta, tau2_fit)
    model = prob.model(v)
    curve_vals = model(tf)
    r = res(theta)
    # propagate the error of the measured P(τ0) through the constraint
    refit = (lambda dP: prob.fit_at(tau2_fit, sol.x, warm_only=True, P0=P_tau0 + dP)[0]) if prob.derive_fe else None
    st = _fit_stats(sol, curve_vals, tf, prob.Pf, r, k, absolute_sigma, P_tau0_err, refit)
    errors = _homogeneous_errors(free, st, prob.derive_fe, P_tau0_err)
    errors["tau2"] = tau2_err
    values = dict(v)
    values["P_tau0"] = P_tau0
    errors["P_tau0"] = P_tau0_err
    return _survival_fit(model, values, errors, free + (("tau2",) if fit_tau2 else ()), st, tf, r, sol, prob.space)


def _parameter_values(d, name: str, names: tuple, required: tuple) -> None:
    """``d`` a dict of parameter names among ``names`` (holding every one of ``required``) to finite numbers."""
    check.mapping(d, name)
    unknown = sorted(set(d) - set(names))
    if unknown:
        raise ConfigError(f"{name} names unknown parameters {unknown}; they are among {names}")
    missing = [n for n in required if n not in d]
    if missing:
        raise ConfigError(f"{name} lacks {', '.join(missing)}")
    for key, value in d.items():
        check.number(value, f"{name}[{key!r}]")


def _homogeneous_start(tf, Pf, tau2, P_tau0, fixed, p0=None):
    """homogeneous_start(tf, Pf, tau2, P_tau0, fixed, p0=None) -> (f_ne, f_e, L, b starts): data-driven starting
    values of the homogeneous fit (``p0`` and ``fixed`` win): f_ne ≈ P(τ2) (below 0.9 P(τ0)), f_e = P(τ0) − f_ne,
    L ≈ the late log-slope of P, and three starts for b unless given."""
    size = check.floats(tf, "tf").size
    check.floats(Pf, "Pf", size=size, of="time tf")
    if size == 0:
        raise ConfigError("tf must hold at least one fitted point")
    _time_or_inf(tau2, "tau2")
    check.number(P_tau0, "P_tau0", minimum=0.0)
    check.mapping(fixed, "fixed")
    _optional_mapping(p0, "p0")
    p0 = dict(p0 or {})

    def p_near(tq):
        return float(np.exp(np.interp(tq, tf, np.log(Pf))))

    fne0 = p0.get("f_ne", fixed.get("f_ne", min(max(p_near(tau2), 1e-8), 0.9 * P_tau0)))
    fe0 = p0.get("f_e", fixed.get("f_e", max(P_tau0 - fne0, 1e-8)))
    late = tf > tau2
    if late.sum() >= 3:
        hl = tf[late] >= np.median(tf[late])
        slope = -np.polyfit(tf[late][hl], np.log(Pf[late][hl]), 1)[0] if hl.sum() >= 2 else 0.05
        L0 = p0.get("L", max(slope, 1e-3))
    else:
        L0 = p0.get("L", 0.05)
    b_starts = (p0["b"],) if "b" in p0 else (0.02, 0.1, 0.5)
    return fne0, fe0, L0, b_starts


@dataclass(frozen=True)
class HomogeneousProblem:
    """The least-squares problem of :func:`fit_survival_model` on its selected points (tf, Pf ± sf).

    ``free`` the fitted parameters (in order: θ), ``fixed`` the held ones,
    ``start`` the starting f_ne, f_e, L and ``b_starts`` the starts for b;
    with ``constrain_total`` (and f_e not fixed) f_e = P(τ0) − f_ne. Each step
    of the fit is a method, testable alone.

    The arguments are checked when the problem is built, a wrong one refused with a ConfigError naming it: tf
    (time), Pf and sf one finite value per time (at least one; Pf ≥ 0, and > 0 in the "log" ``space``; sf > 0), the
    energy path and law as :func:`survival_model` takes them (E0 > 0 (energy), mu, gamma ≥ 0 (1/time), tau0 (time),
    E_c > 0 (energy), ``hazard``), ``space`` "log" or "linear", ``free`` distinct names among f_ne, f_e, L, b,
    ``fixed`` and ``start`` (f_ne, f_e, L) dicts of those names to finite numbers, ``b_starts`` at least one
    b > 0, ``constrain_total`` a bool and P_tau0 ≥ 0. The arrays are kept as float arrays, free and b_starts as
    tuples.

    Examples
    --------
    A constant κ0 = 0.05 with f_e = P(τ0) − f_ne derived: θ = (f_ne, L, b) = (0.1, 0.2, 0.3) at τ2 = 30 gives
    f_e = 0.5 − 0.1.

    >>> prob = HomogeneousProblem(tf=[5.0, 10.0, 20.0], Pf=[0.5, 0.4, 0.3], sf=[0.01, 0.01, 0.01],
    ...                           kappa_of_E=lambda E: np.full(np.shape(E), 0.05), E0=0.3, mu=0.91, gamma=0.01,
    ...                           tau0=5.0, E_c=0.2, hazard="paper", space="log", free=("f_ne", "L", "b"), fixed={},
    ...                           start={"f_ne": 0.1, "f_e": 0.4, "L": 0.05}, b_starts=(0.1,), constrain_total=True,
    ...                           P_tau0=0.5)
    >>> {k: round(v, 12) for k, v in prob.values([0.1, 0.2, 0.3], tau2=30.0).items()}
    {'f_ne': 0.1, 'f_e': 0.4, 'L': 0.2, 'b': 0.3, 'tau2': 30.0}
    >>> HomogeneousProblem(tf=[5.0, 10.0], Pf=[0.5, 0.4], sf=[0.01, 0.01], kappa_of_E=lambda E: E, E0=0.3,
    ...                    mu=0.91, gamma=0.01, tau0=5.0, E_c=0.2, hazard="paper", space="log", free=("f_ne", "tau2"),
    ...                    fixed={}, start={"f_ne": 0.1, "f_e": 0.4, "L": 0.05}, b_starts=(0.1,),
    ...                    constrain_total=True, P_tau0=0.5)
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: free must name distinct parameters among ('f_ne', 'f_e', 'L', 'b'), got ('f_ne', 'tau2')
    """

    tf: np.ndarray
    Pf: np.ndarray
    sf: np.ndarray
    kappa_of_E: Callable
    E0: float
    mu: float
    gamma: float
    tau0: float
    E_c: float
    hazard: str
    space: str
    free: tuple
    fixed: dict
    start: dict
    b_starts: tuple
    constrain_total: bool
    P_tau0: float

    def __post_init__(self):
        tf = check.numbers(self.tf, "tf", flat=True)
        Pf = check.numbers(self.Pf, "Pf", minimum=0.0, flat=True)
        sf = check.numbers(self.sf, "sf", positive=True, flat=True)
        for arr, name in ((Pf, "Pf"), (sf, "sf")):
            if arr.size != tf.size:
                raise ConfigError(f"{name} must have one value per time tf: {arr.size} != {tf.size}")
        if self.space not in ("log", "linear"):
            raise ConfigError(f"space must be 'log' or 'linear', got {self.space!r}")
        if self.space == "log" and not np.all(Pf > 0):
            raise ConfigError("Pf must be > 0 in the log space (its residuals take ln P)")
        check.function(self.kappa_of_E, "kappa_of_E")
        check.number(self.E0, "E0", positive=True)
        check.number(self.mu, "mu")
        check.number(self.gamma, "gamma", minimum=0.0)
        check.number(self.tau0, "tau0")
        check.number(self.E_c, "E_c", positive=True)
        if self.hazard not in HAZARDS:
            raise ConfigError(f"hazard must be one of {HAZARDS}, got {self.hazard!r}")
        names = _HOMOG[:4]
        free = tuple(self.free) if isinstance(self.free, (tuple, list)) else None
        if free is None or len(set(free)) != len(free) or not set(free) <= set(names):
            raise ConfigError(f"free must name distinct parameters among {names}, got {self.free!r}")
        _parameter_values(self.fixed, "fixed", names, ())
        _parameter_values(self.start, "start", names, ("f_ne", "f_e", "L"))
        b_starts = tuple(self.b_starts) if isinstance(self.b_starts, (tuple, list)) else ()
        if not b_starts:
            raise ConfigError(f"b_starts must be a tuple of at least one start for b, got {self.b_starts!r}")
        for i, b in enumerate(b_starts):
            check.number(b, f"b_starts[{i}]", positive=True)
        if not isinstance(self.constrain_total, (bool, np.bool_)):
            raise ConfigError(f"constrain_total must be True or False, got {self.constrain_total!r}")
        check.number(self.P_tau0, "P_tau0", minimum=0.0)
        for name, value in (("tf", tf), ("Pf", Pf), ("sf", sf), ("free", free), ("b_starts", b_starts)):
            object.__setattr__(self, name, value)

    @property
    def derive_fe(self) -> bool:
        return self.constrain_total and "f_e" not in self.fixed

    def bounds(self, P0=None):
        """(lo, hi) of θ: 0 ≤ f_ne ≤ P(τ0) (or 1), 0 ≤ f_e ≤ 1, L ∈ [1e-9, 1e3], b ∈ [1e-6, 1e3]."""
        P0 = self.P_tau0 if P0 is None else P0
        bounds = {
            "f_ne": (0.0, P0 if self.constrain_total else 1.0),
            "f_e": (0.0, 1.0),
            "L": (1e-9, 1e3),
            "b": (1e-6, 1e3),
        }
        return (
            np.array([bounds[n][0] for n in self.free], dtype=float),
            np.array([bounds[n][1] for n in self.free], dtype=float),
        )

    def values(self, theta, tau2, P0=None) -> dict:
        """All parameters from θ: the starts, overridden by ``fixed``, then θ; f_e derived; τ2 set."""
        v = {**self.start, "b": self.b_starts[0]}
        v.update(self.fixed)
        v.update(dict(zip(self.free, theta)))
        if self.derive_fe:
            v["f_e"] = (self.P_tau0 if P0 is None else P0) - v["f_ne"]
        v["tau2"] = tau2
        return v

    def model(self, v: dict) -> SurvivalModelParams:
        return SurvivalModelParams(
            self.kappa_of_E,
            self.E0,
            self.mu,
            self.gamma,
            self.tau0,
            v["tau2"],
            v["f_ne"],
            v["f_e"],
            v["L"],
            v["b"],
            self.E_c,
            self.hazard,
        )

    def starts(self, prev=None, warm_only: bool = False) -> list:
        """Starting θ: a previous solution (warm start) first, then one per start of b."""
        out = []
        if prev is not None:
            out.append(prev)
            if warm_only:
                return out
        for b0 in self.b_starts:
            guess = {**self.start, "b": b0}
            out.append([guess[n] for n in self.free])
        return out

    def fit_at(self, tau2, prev=None, warm_only: bool = False, P0=None):
        """(solution or None, χ², residual function) of the fit with τ2 held at ``tau2``."""
        curve = lambda th: self.model(self.values(th, tau2, P0))(self.tf)
        res = _residual_fn(curve, self.Pf, self.sf, self.space)
        if not self.free:
            r = res(np.array([]))
            return None, float(np.sum(r**2)), res
        sol = _lsq(res, self.starts(prev, warm_only), *self.bounds(P0))
        return sol, float(2 * sol.cost), res

    def profile(self, taus):
        """χ² profile over τ2 (each point warm-started from its neighbour): (χ² array, solutions)."""
        prof, sols, prev = [], [], None
        for tv in taus:
            sol, c2, _ = self.fit_at(tv, prev)
            prev = None if sol is None else sol.x
            prof.append(c2)
            sols.append(prev)
        return np.array(prof), sols

    def fit_tau2(self, absolute_sigma: bool = True):
        """τ2 fitted by profiling χ²: a coarse scan over [τ0, t_last], then a fine one around its minimum; the
        error is the half-width of the Δχ² = 1 region (scaled by χ²/dof unless ``absolute_sigma``), its two ends
        found by root-finding on the profile (:func:`~hhscatter.analysis.dissipative.curve_fit.profile_interval`), not bounded by the scan's steps.
        Returns (τ2, σ_τ2, solution, χ², residual function)."""
        grid = np.linspace(self.tau0 + 1e-9, float(self.tf[-1]), 25)
        prof, _ = self.profile(grid)
        i = int(np.argmin(prof))
        fine = np.linspace(grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)], 21)
        fprof, fsols = self.profile(fine)
        j = int(np.argmin(fprof))
        tau2_best = float(fine[j])
        sol, c2min, res = self.fit_at(tau2_best, fsols[j])
        dof = self.tf.size - len(self.free) - 1
        scale = 1.0 if absolute_sigma else max(c2min / max(dof, 1), 1e-300)
        warm = None if sol is None else sol.x

        def chi2_at(tv):
            return self.fit_at(float(tv), warm)[1]

        lo, hi = profile_interval(chi2_at, tau2_best, c2min, grid[0], grid[-1], delta=scale, step=fine[1] - fine[0])
        return tau2_best, float((hi - lo) / 2), sol, c2min, res


def _homogeneous_errors(free, st, derive_fe: bool, P_tau0_err: float) -> dict:
    """1σ errors of f_ne, f_e, L, b from the fit statistics; f_e = P(τ0) − f_ne carries P(τ0)'s error."""
    errors = {n: 0.0 for n in _HOMOG}
    for i, n in enumerate(free):
        errors[n] = float(np.sqrt(max(st.cov[i, i], 0.0)))
    if derive_fe:
        i_f = free.index("f_ne") if "f_ne" in free else None
        var_fit = st.cov_fit[i_f, i_f] if i_f is not None else 0.0
        dfe_dP = 1.0 - (st.sens[i_f] if i_f is not None else 0.0)
        errors["f_e"] = float(np.sqrt(max(var_fit, 0.0) + (dfe_dP * P_tau0_err) ** 2))
    return errors
