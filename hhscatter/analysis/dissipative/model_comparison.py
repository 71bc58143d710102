"""What fitted survival models of dissipative scattering give: the τ1 they predict (Eq. (eqn:tau1)), their
comparison side by side, and the fitting rule that fits them to a measured P(t) (any system). The models and their fits are :mod:`hhscatter.analysis.dissipative.survival_model`.

Units: time in model units, rates in 1/time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd
from scipy import optimize

from hhscatter.analysis.dissipative.curve_fit import best_of
from hhscatter.analysis.dissipative.mixture import MixtureComponents, fit_mixture_model
from hhscatter.analysis.dissipative.survival_model import HAZARDS, fit_survival_model
from hhscatter.analysis.dissipative.transitions import tau2_predicted
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "best_fit",
    "better_fit",
    "compare_fits",
    "fit_homogeneous_hazards",
    "fit_mixture_hazards",
    "plateau_level",
    "predict_tau1",
    "survival_fit_points",
]


# ---------------------------------------------------------------------------
# τ1 from the model
# ---------------------------------------------------------------------------
def _curve(t, P, names=("t", "P")) -> None:
    """A measured curve: increasing finite times ``t`` (at least one) and P with one value per time (NaN may stand)."""
    if np.ndim(t) != 1:
        raise ConfigError(f"{names[0]} must be a 1-D array of times, got {type(t).__name__}")
    t = check.numbers(t, names[0])
    check.floats(P, names[1], size=t.size, of=f"time {names[0]}")
    if np.any(np.diff(t) < 0):
        raise ConfigError(f"{names[0]} must be increasing")


def _hazards(hazards) -> None:
    if isinstance(hazards, (str, bytes, dict)) or not isinstance(hazards, (list, tuple)) or not hazards:
        raise ConfigError(f"hazards must be a non-empty list of {HAZARDS}, got {hazards!r}")
    for h in hazards:
        if h not in HAZARDS:
            raise ConfigError(f"hazards must be a non-empty list of {HAZARDS}, got {hazards!r}")


_FIT_FIELDS = ("n_points", "free", "chi2", "dof", "chi2_red", "rms_log_residual", "aic")


def _as_curve(P_0):
    if callable(P_0):
        return P_0
    tg, Pg = (np.asarray(a, dtype=float) for a in P_0)
    ok = np.isfinite(Pg) & (Pg > 0)
    tg, lg = tg[ok], np.log(Pg[ok])

    def f(t):
        t = np.asarray(t, dtype=float)
        out = np.exp(np.interp(t, tg, lg))
        return np.where((t < tg[0]) | (t > tg[-1]), np.nan, out)

    f.t_end = float(tg[-1])
    return f


def predict_tau1(params, P_0, alpha: float = 2.0, *, t_max: float | None = None, n_grid: int = 20001):
    """predict_tau1(params, P_0, alpha=2.0, *, t_max=None) -> float or None.

    Predicted τ1 (Fig. 6b dashed line): solves Eq. (eqn:tau1),
    min{t ≥ τ0 : P_model(t) = α P_0(t)}, with P_model given by ``params``
    (a :class:`SurvivalModelParams`, :class:`MixtureModelParams`, a
    :class:`SurvivalFit`, or any object with ``tau0`` that is callable on t).

    ``P_0`` is the conservative survival curve: a callable P_0(t) or a pair
    (t_grid, P0_values), interpolated linearly in log P (NaN outside the
    grid).  The condition is scanned on ``n_grid`` points in [τ0, t_max]
    (default: the end of the P_0 grid, or τ0 + 3(τ2 − τ0) for a callable)
    and the first sign change of ln P_model − ln(α P_0) is refined with
    Brent's method.  Returns τ0 if the condition already holds at τ0, None if
    it never does.
    """
    if hasattr(params, "params") and not hasattr(params, "tau0"):
        params = params.params
    if not (callable(params) and hasattr(params, "tau0")):
        raise ConfigError(f"params must be model parameters with tau0 that give P(t), got {type(params).__name__}")
    if not callable(P_0):
        if isinstance(P_0, (str, bytes, dict)) or not hasattr(P_0, "__len__") or len(P_0) != 2:
            raise ConfigError(f"P_0 must be a function P_0(t) or a pair (t_grid, P0_values), got {P_0!r}")
        _curve(P_0[0], P_0[1], ("P_0[0]", "P_0[1]"))
    check.number(alpha, "alpha", positive=True)
    if t_max is not None:
        check.number(t_max, "t_max")
    check.count(n_grid, "n_grid", 2)
    tau0 = float(params.tau0)
    f0 = _as_curve(P_0)
    if t_max is None:
        if hasattr(f0, "t_end"):
            t_max = f0.t_end
        else:
            tau2 = params.tau2_k if hasattr(params, "tau2_k") else params.tau2
            tau2 = float(np.max(np.atleast_1d(tau2)))
            t_max = tau0 + 3 * max(tau2 - tau0, 1.0)
    if t_max <= tau0:
        return None
    tt = np.linspace(tau0, t_max, n_grid)

    def D(x):
        pm = np.asarray(params(x), dtype=float)
        p0 = np.asarray(f0(x), dtype=float)
        return _log_ratio_d(pm, p0, alpha)

    d = D(tt)
    if d[0] >= 0:
        return tau0
    hit = np.flatnonzero(d >= 0)
    if hit.size == 0:
        return None
    j = int(hit[0])
    a, b = tt[j - 1], tt[j]
    if not np.isfinite(d[j]) or not np.isfinite(d[j - 1]):
        return float(b)
    try:
        return float(optimize.brentq(lambda x: float(D(x)), a, b, xtol=1e-10))
    except ValueError:
        return float(b)


def _log_ratio_d(pm, p0, alpha):
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.log(pm) - np.log(alpha * p0)
    d = np.where((p0 <= 0) & (pm > 0), np.inf, d)
    return np.where(np.isnan(d), -np.inf, d)


def compare_fits(fits: dict) -> pd.DataFrame:
    """compare_fits({name: SurvivalFit, ...}) -> DataFrame of goodness of fit, one row per model.

    Columns: n_points, n_free, chi2, dof, chi2_red, rms_log_residual, aic.
    The comparison is meaningful only for fits on the same data selection
    (equal n_points, same τ0, t_max, P_min and residual space).
    """
    check.mapping(fits, "fits", min_size=1)
    for name, f in fits.items():
        check.having(f, f"fits[{name!r}]", _FIT_FIELDS, "a SurvivalFit")
    rows = []
    for name, f in fits.items():
        rows.append(
            {
                "model": name,
                "n_points": f.n_points,
                "n_free": len(f.free),
                "chi2": f.chi2,
                "dof": f.dof,
                "chi2_red": f.chi2_red,
                "rms_log_residual": f.rms_log_residual,
                "aic": f.aic,
            }
        )
    return pd.DataFrame(rows).set_index("model")


def better_fit(fits: dict) -> str | None:
    """better_fit({name: SurvivalFit, ...}) -> name of the fit with the smallest RMS log residual (None on a tie).

    For the same model, Eq. (eqn:surv_prob_model), fitted with different
    fixed inputs (e.g. the κ0(E) law and μ fitted by us or stated by the
    paper): the RMS of ln P_model − ln P (dimensionless) says which inputs
    reproduce the simulated P(t) better.  The RMS rather than χ² because the
    Kaplan–Meier points are correlated and χ² is only indicative (see
    :class:`SurvivalFit`); both fits have the same free parameters here.
    The fits must share their fitted points (same ``t_fit``), else the
    comparison means nothing: ValueError.
    """
    check.mapping(fits, "fits")
    if len(fits) < 2:
        raise ConfigError("better_fit needs at least two fits")
    for name, f in fits.items():
        check.having(f, f"fits[{name!r}]", ("t_fit", "rms_log_residual"), "a SurvivalFit")
    items = list(fits.items())
    t_ref = np.asarray(items[0][1].t_fit)
    for name, f in items[1:]:
        if not np.array_equal(np.asarray(f.t_fit), t_ref):
            raise ConfigError(
                f"fit {name!r} was made on other points than {items[0][0]!r}; "
                "compare fits on the same data selection only"
            )
    rms = np.array([f.rms_log_residual for _, f in items], dtype=float)
    if not np.isfinite(rms).all():
        raise ConfigError(f"non-finite RMS log residual: {dict(zip(fits, rms))}")
    best = np.flatnonzero(rms == rms.min())
    return None if best.size > 1 else items[int(best[0])][0]


# ---------------------------------------------------------------------------
# the fitting rule: which points of a measured P(t) are fitted, and the fits on them
# ---------------------------------------------------------------------------
def survival_fit_points(t, P, P_err, tau0: float, fit_dt: float, n: int, min_count: float):
    """survival_fit_points(t, P, P_err, τ0, fit_dt, n, min_count) -> (t, P, P_err) of the fitted points.

    The curve's points nearest to the coarse grid τ0, τ0 + fit_dt, … (Kaplan–Meier points are correlated: a
    coarse grid keeps the fit's χ² indicative), kept where N·P ≥ ``min_count`` (log residuals need counts ≫ 1)
    and P_err > 0. Times in time units.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 10.0, 0.5); P = np.exp(-0.3 * t)
    >>> survival_fit_points(t, P, 0.01 * P, 1.0, 2.0, 1000, 20)[0].tolist()
    [1.0, 3.0, 5.0, 7.0, 9.0]
    """
    _curve(t, P)
    check.floats(P_err, "P_err", size=len(t), of="time t")
    check.number(tau0, "tau0")
    check.number(fit_dt, "fit_dt", positive=True)
    check.number(n, "n", positive=True)
    check.number(min_count, "min_count", minimum=0.0)
    grid = np.arange(tau0, t[-1] + 1e-9, fit_dt)
    idx = np.clip(np.searchsorted(t, grid), 0, t.size - 1)
    idx = np.unique(idx)
    sel = (P[idx] * n >= min_count) & (P_err[idx] > 0)
    return t[idx][sel], P[idx][sel], P_err[idx][sel]


def best_fit(fit_fn: Callable, starts):
    """best_fit(fit_fn, starts) -> the fit with the smallest χ² over several starting-value dicts.

    The χ² surface has local minima (the settling branch can be traded for a lower trapped fraction);
    starts whose fit raises RuntimeError or ValueError are skipped; none left is a RuntimeError.
    """
    return best_of(
        fit_fn,
        starts,
        lambda f: f.chi2,
        (RuntimeError, ValueError),
        "survival-model fit failed from every starting point",
    )


def plateau_level(t, P, t_q: float) -> float:
    """plateau_level(t, P, t_q) -> P at time t_q (log-linear interpolation): the trapped fraction before settling
    starts, when t_q is late in the escape regime."""
    _curve(t, P)
    check.number(t_q, "t_q")
    return float(np.exp(np.interp(t_q, t, np.log(np.maximum(P, 1e-300)))))


def fit_homogeneous_hazards(t, P, P_err, tf, Pf, sf, *, kappa, E0, mu, gamma, tau0, E_c, hazards, fit_tau2, P_min):
    """fit_homogeneous_hazards(curve, fitted points, *, κ0(E), E0, μ, γ, τ0, E_c, hazards, fit_tau2, P_min)
    -> {hazard: SurvivalFit}: the homogeneous model, Eq. (eqn:surv_prob_model), fitted on the points of
    :func:`survival_fit_points`.

    ``t, P, P_err``: the whole Kaplan–Meier curve (P(τ0) and the starting trapped fraction are read from it);
    ``tf, Pf, sf``: the fitted points (:func:`survival_fit_points`). P(τ0) is held; three starts (data-driven,
    and f_ne = P at τ0 + 0.85 (τ2 − τ0) with (L, b) = (1, 1) and (3, 0.3)), the best χ² kept
    (:func:`best_fit`). Units: t in time units, E in energy units, γ in 1/time.
    """
    _curve(t, P)
    check.floats(P_err, "P_err", size=len(t), of="time t")
    _curve(tf, Pf, ("tf", "Pf"))
    check.floats(sf, "sf", size=len(tf), of="time tf")
    check.function(kappa, "kappa")
    check.number(E0, "E0", positive=True)
    check.number(mu, "mu")
    check.number(gamma, "gamma", minimum=0.0)
    check.number(tau0, "tau0")
    check.number(E_c, "E_c", positive=True)
    _hazards(hazards)
    check.number(P_min, "P_min")
    P_tau0 = plateau_level(t, P, tau0)
    tau2 = tau2_predicted(E0, E_c, mu, gamma)
    fne = min(plateau_level(t, P, tau0 + 0.85 * (tau2 - tau0)), 0.95 * P_tau0)
    starts = [None, {"f_ne": fne, "L": 1.0, "b": 1.0}, {"f_ne": fne, "L": 3.0, "b": 0.3}]
    fits = {}
    for h in hazards:
        fits[h] = best_fit(
            lambda p0, h=h: fit_survival_model(
                tf,
                Pf,
                sf,
                kappa_of_E=kappa,
                E0=E0,
                mu=mu,
                gamma=gamma,
                tau0=tau0,
                E_c=E_c,
                hazard=h,
                fit_tau2=fit_tau2,
                P_min=P_min,
                P_tau0=P_tau0,
                p0=p0,
            ),
            starts,
        )
    return fits


def fit_mixture_hazards(t, P, tf, Pf, sf, comps, *, kappa, tau0, E_c, hazards, mode, P_min):
    """{hazard: MixtureFit}: the mixture model of sub-ensembles fitted on the points of
    :func:`survival_fit_points`.

    ``t, P``: the whole Kaplan–Meier curve (P(τ0) and the starting trapped fractions are read from it);
    ``tf, Pf, sf``: the fitted points (:func:`survival_fit_points`); ``comps`` the sub-ensembles
    (:func:`~hhscatter.analysis.dissipative.mixture.mixture_components`); ``kappa`` κ0(E) (1/time); ``mode``
    "shared" (one trapped fraction φ of P(τ0)) or "free" (one f_ne,k per sub-ensemble). P(τ0) is held; three
    starts (data-driven, and the trapped fraction P at τ0 + 0.85 (τ2,min − τ0) — shared, or handed to the
    low-energy sub-ensembles first, which reach E_c first — with (L, b) = (1, 1) and (3, 0.3)), the best χ²
    kept (:func:`best_fit`). Eq. (eqn:surv_prob_model) per sub-ensemble, τ2,k of Eq. (eq:tau2) with its own
    μ_k. Units: t in time units, E in energy units.

    Examples
    --------
    >>> import pandas as pd
    >>> from hhscatter.analysis.dissipative.mixture import mixture_components
    >>> from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
    >>> rng = np.random.default_rng(1)
    >>> tt = np.arange(0.0, 101.0, 2.0)
    >>> E = 0.3 * np.exp(-0.9 * 0.01 * tt)[None, :] * rng.uniform(0.95, 1.05, (40, 1))
    >>> snaps = pd.DataFrame({"traj_id": np.repeat(np.arange(40), tt.size), "t": np.tile(tt, 40),
    ...                       "energy": E.ravel()})
    >>> comps = mixture_components(snaps, gamma=0.01, t_ref=5.0, n_components=2, fit_window=(5.0, 100.0))
    >>> t = np.arange(0.0, 200.0, 0.5); P = 0.2 + 0.8 * np.exp(-0.15 * t)
    >>> tf, Pf, sf = survival_fit_points(t, P, 0.01 * P, 5.0, 2.0, 10**5, 20)
    >>> fits = fit_mixture_hazards(t, P, tf, Pf, sf, comps, kappa=PiecewiseKappa(E_c=1 / 6), tau0=5.0,
    ...                            E_c=1 / 6, hazards=["paper"], mode="shared", P_min=1e-4)
    >>> sorted(fits), bool(np.isfinite(fits["paper"].chi2))
    (['paper'], True)
    """
    _curve(t, P)
    _curve(tf, Pf, ("tf", "Pf"))
    check.floats(sf, "sf", size=len(tf), of="time tf")
    check.instance(comps, "comps", MixtureComponents)
    check.function(kappa, "kappa")
    check.number(tau0, "tau0")
    check.number(E_c, "E_c", positive=True)
    _hazards(hazards)
    if mode not in ("shared", "free"):
        raise ConfigError(f"mode must be 'shared' or 'free', got {mode!r}")
    check.number(P_min, "P_min")
    P_tau0 = plateau_level(t, P, tau0)
    t2 = float(np.min(comps.tau2(E_c)))
    fne = min(plateau_level(t, P, tau0 + 0.85 * max(t2 - tau0, 0.0)), 0.95 * P_tau0)
    if mode == "shared":
        alt = {"phi": fne / P_tau0}
    else:  # trapped orbits first assigned to the low-energy sub-ensembles (they reach E_c first)
        alt, left = {}, fne
        for k in np.argsort(comps.E_ref):
            cap = 0.99 * comps.weights[k] * P_tau0
            alt[f"f_ne_{k}"] = max(min(left, cap), 1e-9)
            left -= min(left, cap)
    starts = [None, {**alt, "L": 1.0, "b": 1.0}, {**alt, "L": 3.0, "b": 0.3}]
    return {
        h: best_fit(
            lambda p0, h=h: fit_mixture_model(
                tf,
                Pf,
                sf,
                comps,
                kappa_of_E=kappa,
                tau0=tau0,
                E_c=E_c,
                P_tau0=P_tau0,
                fne_mode=mode,
                hazard=h,
                P_min=P_min,
                p0=p0,
            ),
            starts,
        )
        for h in hazards
    }
