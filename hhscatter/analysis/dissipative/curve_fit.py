"""The weighted least squares the survival-model fits share (:mod:`~hhscatter.analysis.dissipative.survival_model`,
:mod:`~hhscatter.analysis.dissipative.mixture`, :mod:`~hhscatter.analysis.dissipative.model_comparison`): the data
points a fit uses, residuals in log or linear space, the best of several starts, the covariance, the goodness of fit
(χ², dof, χ²/dof, RMS of log residuals, AIC), the sensitivity to the measured P(τ0), and profile-likelihood
intervals. P is a survival probability (dimensionless), t in time units.

Examples
--------
>>> lo, hi = profile_interval(lambda x: (x - 2.0) ** 2, 2.0, 0.0, 0.0, 10.0)
>>> round(lo, 6), round(hi, 6)
(1.0, 3.0)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["best_of", "profile_interval"]


# ---------------------------------------------------------------------------
def _data(t, P, P_err):
    """(t, P, P_err) as flat float arrays of one length (NaN may stand in P and P_err: such points are dropped)."""
    t = check.floats(t, "t")
    return t, check.floats(P, "P", size=t.size, of="time t"), check.floats(P_err, "P_err", size=t.size, of="time t")


def _select_points(t, P, P_err, tau0, t_max, P_min):
    t, P, P_err = _data(t, P, P_err)
    check.number(tau0, "tau0")
    if t_max is not None:
        check.real(t_max, "t_max")
    check.number(P_min, "P_min")
    sel = (t >= tau0) & np.isfinite(P) & np.isfinite(P_err) & (P_err > 0) & (P > P_min)
    if t_max is not None:
        sel &= t <= t_max
    return t[sel], P[sel], P_err[sel]


def _p_at(t, P, P_err, t0):
    """(P(t0), σ_P(t0)) by log-linear interpolation of the data."""
    _data(t, P, P_err)
    check.number(t0, "t0")
    t = np.asarray(t, dtype=float)
    P = np.asarray(P, dtype=float)
    E = np.asarray(P_err, dtype=float)
    ok = np.isfinite(P) & (P > 0)
    t, P, E = t[ok], P[ok], E[ok]
    if t.size == 0 or t0 < t[0] or t0 > t[-1]:
        raise ConfigError("cannot interpolate P at tau0 from the data; pass P_tau0")
    return float(np.exp(np.interp(t0, t, np.log(P)))), float(np.interp(t0, t, E))


def _residual_fn(curve, P, sig, space):
    check.function(curve, "curve")
    check.floats(sig, "sig", size=check.floats(P, "P").size, of="point of P")
    if space == "log":
        y, s = np.log(P), sig / P

        def res(theta):
            m = curve(theta)
            with np.errstate(divide="ignore", invalid="ignore"):
                lm = np.log(np.where(m > 0, m, 1e-300))
            lm = np.where(np.isfinite(lm), lm, -700.0)
            return (lm - y) / s

    elif space == "linear":

        def res(theta):
            m = curve(theta)
            return (np.where(np.isfinite(m), m, 0.0) - P) / sig

    else:
        raise ConfigError(f"space must be 'log' or 'linear', got {space!r}")
    return res


def best_of(fit_fn, starts, cost, errors, message):
    """The result of ``fit_fn(start)`` with the smallest ``cost(result)`` over several starting points.

    A fit whose cost surface has local minima is run from each start of ``starts``; a start whose fit raises one of
    ``errors`` (an exception class or a tuple of them) is skipped, and none left is a RuntimeError(``message``).
    The cost is in the unit ``cost`` returns (a χ², a sum of squares: dimensionless for normalised residuals).

    Examples
    --------
    >>> def fit(x0):
    ...     if x0 < 0:
    ...         raise ValueError("start outside the domain")
    ...     return {"x": x0, "cost": (x0 - 2.0) ** 2}
    >>> best_of(fit, [-1.0, 0.5, 2.5], lambda r: r["cost"], ValueError, "no start converged")["x"]
    2.5
    >>> best_of(fit, [-1.0], lambda r: r["cost"], ValueError, "no start converged")
    Traceback (most recent call last):
    ...
    RuntimeError: no start converged
    """
    check.function(fit_fn, "fit_fn")
    check.function(cost, "cost")
    if isinstance(starts, (str, bytes, dict)) or starts is None or not hasattr(starts, "__iter__"):
        raise ConfigError(f"starts must be a list of starting points, got {type(starts).__name__}")
    kinds = errors if isinstance(errors, tuple) else (errors,)
    if not all(isinstance(k, type) and issubclass(k, BaseException) for k in kinds):
        raise ConfigError(f"errors must be an exception class or a tuple of them, got {errors!r}")
    if not isinstance(message, str):
        raise ConfigError(f"message must be a str, got {type(message).__name__}")
    best = None
    for x0 in starts:
        try:
            r = fit_fn(x0)
        except errors:
            continue
        if best is None or cost(r) < cost(best):
            best = r
    if best is None:
        raise RuntimeError(message)
    return best


def _lsq(res, starts, lo, hi):
    """Best least_squares solution over several starting points."""
    check.function(res, "res")
    check.floats(hi, "hi", size=check.floats(lo, "lo").size, of="bound of lo")

    def solve(x0):
        x0 = np.clip(np.asarray(x0, dtype=float), lo + 1e-12 * (np.abs(lo) + 1), hi - 1e-12 * (np.abs(hi) + 1))
        return optimize.least_squares(res, x0, bounds=(lo, hi), method="trf", x_scale="jac", max_nfev=2000)

    return best_of(solve, starts, lambda r: r.cost, ValueError, "survival fit failed for all starting points")


def _covariance(J, chi2_red, absolute_sigma):
    if np.ndim(J) != 2 or check.floats(J, "J").size == 0:
        raise ConfigError("J must be a non-empty 2-D array (the Jacobian)")
    check.real(chi2_red, "chi2_red")
    cov = np.linalg.pinv(J.T @ J)
    if not absolute_sigma:
        cov = cov * chi2_red
    return cov


def _goodness(curve_vals, t, P, res_norm, k):
    size = check.floats(t, "t").size
    check.floats(curve_vals, "curve_vals", size=size, of="time t")
    check.floats(P, "P", size=size, of="time t")
    check.floats(res_norm, "res_norm")
    check.count(k, "k", 0)
    n = t.size
    chi2 = float(np.sum(res_norm**2))
    dof = n - k
    with np.errstate(divide="ignore", invalid="ignore"):
        lr = np.log(curve_vals) - np.log(P)
    lr = lr[np.isfinite(lr)]
    rms = float(np.sqrt(np.mean(lr**2))) if lr.size else float("nan")
    return chi2, dof, (chi2 / dof if dof > 0 else float("nan")), rms, chi2 + 2 * k


@dataclass(frozen=True)
class _FitStats:
    """Post-fit statistics shared by the homogeneous and the mixture fit."""

    chi2: float
    dof: int
    chi2_red: float
    rms: float
    aic: float
    cov_fit: np.ndarray  # covariance of the free parameters from the fit alone
    sens: np.ndarray  # ∂θ/∂P(τ0) from a re-fit at P(τ0) + σ_P(τ0)
    cov: np.ndarray  # cov_fit plus the propagated error of the measured P(τ0)


def _fit_stats(sol, curve_vals, t, P, r, k, absolute_sigma, P_tau0_err, refit=None) -> _FitStats:
    """Goodness of fit, covariance and the P(τ0) sensitivity; ``refit(P_shift)`` -> solution or None."""
    if sol is not None and not (hasattr(sol, "x") and hasattr(sol, "jac")):
        raise ConfigError(f"sol must be a least-squares solution (with x and jac) or None, got {type(sol).__name__}")
    check.number(P_tau0_err, "P_tau0_err", minimum=0.0)
    if refit is not None:
        check.function(refit, "refit")
    chi2, dof, chi2_red, rms, aic = _goodness(curve_vals, t, P, r, k)
    cov_fit = _covariance(sol.jac, chi2_red, absolute_sigma) if sol is not None else np.zeros((0, 0))
    sens = np.zeros(0 if sol is None else sol.x.size)
    if refit is not None and P_tau0_err > 0 and sol is not None:
        sens = (refit(P_tau0_err).x - sol.x) / P_tau0_err
    return _FitStats(chi2, dof, chi2_red, rms, aic, cov_fit, sens, cov_fit + np.outer(sens, sens) * P_tau0_err**2)


def profile_interval(
    chi2_of,
    best: float,
    chi2_min: float,
    lo_edge: float,
    hi_edge: float,
    *,
    delta: float = 1.0,
    step: float | None = None,
    xtol: float = 1e-9,
) -> tuple[float, float]:
    """profile_interval(chi2_of, best, chi2_min, lo_edge, hi_edge, *, delta=1, step=None) -> (lo, hi): the ends of
    the region χ²(x) ≤ χ²_min + Δ of a profile χ²(x) around its minimum ``best``, by root-finding on each side.

    From ``best`` each side steps outward (``step``, default 1 % of the range,
    doubling) until the profile exceeds χ²_min + Δ, then
    :func:`scipy.optimize.brentq` finds the crossing. A side whose profile does
    not reach it before ``lo_edge``/``hi_edge`` ends there (the interval is then
    the allowed range on that side: the data do not bound it).
    """
    check.function(chi2_of, "chi2_of")
    check.number(best, "best")
    check.number(chi2_min, "chi2_min")
    check.number(lo_edge, "lo_edge")
    check.number(hi_edge, "hi_edge")
    if not lo_edge < hi_edge:
        raise ConfigError(f"lo_edge < hi_edge is needed, got {lo_edge!r} and {hi_edge!r}")
    check.number(delta, "delta", positive=True)
    if step is not None:
        check.number(step, "step", positive=True)
    check.number(xtol, "xtol", positive=True)
    target = float(chi2_min) + float(delta)

    def g(x):
        return float(chi2_of(x)) - target

    step = float(step) if step else 0.01 * (hi_edge - lo_edge)
    ends = []
    for sign, edge in ((-1.0, lo_edge), (1.0, hi_edge)):
        inner, h, end = float(best), step, None
        while end is None:
            outer = float(best) + sign * h
            if sign * (outer - edge) >= 0:
                end = edge if g(edge) <= 0 else float(optimize.brentq(g, *sorted((inner, edge)), xtol=xtol))
            elif g(outer) > 0:
                end = float(optimize.brentq(g, *sorted((inner, outer)), xtol=xtol))
            else:
                inner, h = outer, 2 * h
        ends.append(end)
    return ends[0], ends[1]
