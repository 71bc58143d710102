"""What fitted survival models of dissipative scattering give: the τ1 they predict (Eq. (eqn:tau1)) and their
comparison side by side. The models and their fits are :mod:`hhscatter.analysis.dissipative.survival_model` and
:mod:`hhscatter.analysis.dissipative.mixture`.

Units: time in model units, rates in 1/time.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import optimize

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["better_fit", "compare_fits", "predict_tau1"]


# ---------------------------------------------------------------------------
# τ1 from the model
# ---------------------------------------------------------------------------
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

    Predicted τ1: solves Eq. (eqn:tau1),
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

    Examples
    --------
    The model against the conservative curve P_0 = 0.5 e^{−κ0(E0)(t − τ0)}: at the τ1 found, P_model = 2 P_0.

    >>> from hhscatter.analysis.dissipative.survival_model import SurvivalModelParams
    >>> from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
    >>> kappa = PiecewiseKappa(1 / 6, 13.63, 0.03, 1.41, 0.27)
    >>> params = SurvivalModelParams(kappa, 0.3, 0.91, 0.01, 5.0, 64.59, 0.1, 0.4, 0.1, 0.2, 1 / 6)
    >>> P_0 = lambda t: 0.5 * np.exp(-float(kappa(0.3)) * (np.asarray(t) - 5.0))
    >>> tau1 = predict_tau1(params, P_0, t_max=200.0)
    >>> round(tau1, 3), round(float(params(tau1)) / float(P_0(tau1)), 9)
    (12.7, 2.0)
    """
    if hasattr(params, "params") and not hasattr(params, "tau0"):
        params = params.params
    if not (callable(params) and hasattr(params, "tau0")):
        raise ConfigError(f"params must be model parameters with tau0 that give P(t), got {type(params).__name__}")
    if not callable(P_0):
        if isinstance(P_0, (str, bytes, dict)) or not hasattr(P_0, "__len__") or len(P_0) != 2:
            raise ConfigError(f"P_0 must be a function P_0(t) or a pair (t_grid, P0_values), got {P_0!r}")
        check.curve(P_0[0], P_0[1], ("P_0[0]", "P_0[1]"))
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

    Examples
    --------
    The same data fitted with the literal ("paper") and the integrated escape factor; the data were made with the
    first, whose χ²/dof is near 1.

    >>> from hhscatter.analysis.dissipative.survival_model import fit_survival_model, survival_model_sample
    >>> from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
    >>> kappa = PiecewiseKappa(E_c=1 / 6, a2=13.63, a1=0.03, slope=1.41, E_switch=0.27)
    >>> kw = dict(kappa_of_E=kappa, E0=0.3, mu=0.91, gamma=0.01, tau0=5.0, E_c=1 / 6)
    >>> t, N = np.arange(0.0, 301.0), 100_000
    >>> P, P_err = survival_model_sample(t, N, **kw, f_ne=0.1, f_e=0.4, L=0.1, b=0.2)      # N orbits, binomial noise
    >>> fits = {h: fit_survival_model(t, P, P_err, **kw, P_min=20 / N, hazard=h) for h in ("paper", "integrated")}
    >>> table = compare_fits(fits)
    >>> table[["n_points", "n_free", "dof"]].values.tolist(), table["chi2_red"].round(1).tolist()
    ([[123, 3, 120], [123, 3, 120]], [1.3, 3295.9])
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
    fixed inputs (e.g. the κ0(E) law and μ fitted from the data or taken from
    a reference): the RMS of ln P_model − ln P (dimensionless) says which inputs
    reproduce the simulated P(t) better.  The RMS rather than χ² because the
    Kaplan–Meier points are correlated and χ² is only indicative (see
    :class:`SurvivalFit`); both fits have the same free parameters here.
    The fits must share their fitted points (same ``t_fit``), else the
    comparison means nothing: ValueError.

    Examples
    --------
    Data made with one κ0(E) law; the same model fitted with it and with another law: the first fits better.

    >>> from hhscatter.analysis.dissipative.survival_model import fit_survival_model, survival_model_sample
    >>> from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
    >>> kappa = PiecewiseKappa(E_c=1 / 6, a2=13.63, a1=0.03, slope=1.41, E_switch=0.27)
    >>> kw = dict(kappa_of_E=kappa, E0=0.3, mu=0.91, gamma=0.01, tau0=5.0, E_c=1 / 6)
    >>> t, N = np.arange(0.0, 301.0), 100_000
    >>> P, P_err = survival_model_sample(t, N, **kw, f_ne=0.1, f_e=0.4, L=0.1, b=0.2)      # N orbits, binomial noise
    >>> other = dict(kw, kappa_of_E=PiecewiseKappa(1 / 6, 10.69, 0.282, 1.396, 0.2709))
    >>> fits = {"generating": fit_survival_model(t, P, P_err, **kw, P_min=20 / N),
    ...         "other": fit_survival_model(t, P, P_err, **other, P_min=20 / N)}
    >>> better_fit(fits), round(fits["generating"].rms_log_residual, 3), round(fits["other"].rms_log_residual, 3)
    ('generating', 0.065, 0.116)
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
