"""The fitting rule of the dissipative figures: which points of a measured P(t) the survival models are fitted on,
from which starts, and the fits of every hazard on them.

:func:`survival_fit_points` picks the points (a coarse grid from τ0, enough survivors); :func:`fit_homogeneous_hazards`
and :func:`fit_mixture_hazards` fit the homogeneous model, Eq. (eqn:surv_prob_model), and the mixture of
sub-ensembles for each hazard from three starts (:func:`best_fit` keeps the smallest χ²), with P(τ0) held at the
curve's value (:func:`plateau_level`). The models themselves and their general fits are
:func:`~hhscatter.analysis.dissipative.survival_model.fit_survival_model` and
:func:`~hhscatter.analysis.dissipative.mixture.fit_mixture_model`. Nothing here reads a file. Units: time in model
units, rates in 1/time, energies in energy units.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hhscatter.analysis.dissipative.curve_fit import best_of
from hhscatter.analysis.dissipative.mixture import MixtureComponents, fit_mixture_model
from hhscatter.analysis.dissipative.survival_model import HAZARDS, fit_survival_model
from hhscatter.analysis.dissipative.transitions import tau2_predicted
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["best_fit", "fit_homogeneous_hazards", "fit_mixture_hazards", "plateau_level", "survival_fit_points"]


def _hazards(hazards) -> None:
    if isinstance(hazards, (str, bytes, dict)) or not isinstance(hazards, (list, tuple)) or not hazards:
        raise ConfigError(f"hazards must be a non-empty list of {HAZARDS}, got {hazards!r}")
    for h in hazards:
        if h not in HAZARDS:
            raise ConfigError(f"hazards must be a non-empty list of {HAZARDS}, got {hazards!r}")


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
    check.curve(t, P)
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

    The χ² surface has local minima (the settling branch can be traded for a lower never-escaping fraction);
    starts whose fit raises RuntimeError or ValueError are skipped; none left is a RuntimeError.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> def fit(p0):
    ...     if p0 is None:
    ...         raise RuntimeError("no convergence")
    ...     return SimpleNamespace(chi2=(p0["L"] - 2.0) ** 2)
    >>> best_fit(fit, [None, {"L": 1.0}, {"L": 2.5}]).chi2
    0.25
    """
    return best_of(
        fit_fn,
        starts,
        lambda f: f.chi2,
        (RuntimeError, ValueError),
        "survival-model fit failed from every starting point",
    )


def plateau_level(t, P, t_q: float) -> float:
    """plateau_level(t, P, t_q) -> P at time t_q (log-linear interpolation): the never-escaping fraction before settling
    starts, when t_q is late in the escape regime. Times in time units.

    Examples
    --------
    >>> round(plateau_level(np.array([0.0, 1.0, 2.0]), np.array([1.0, 0.5, 0.25]), 1.5), 6)  # 2^−1.5
    0.353553
    """
    check.curve(t, P)
    check.number(t_q, "t_q")
    return float(np.exp(np.interp(t_q, t, np.log(np.maximum(P, 1e-300)))))


def fit_homogeneous_hazards(t, P, P_err, tf, Pf, sf, *, kappa, E0, mu, gamma, tau0, E_c, hazards, fit_tau2, P_min):
    """fit_homogeneous_hazards(curve, fitted points, *, κ0(E), E0, μ, γ, τ0, E_c, hazards, fit_tau2, P_min)
    -> {hazard: SurvivalFit}: the homogeneous model, Eq. (eqn:surv_prob_model), fitted on the points of
    :func:`survival_fit_points`.

    ``t, P, P_err``: the whole Kaplan–Meier curve (P(τ0) and the starting never-escaping fraction are read from it);
    ``tf, Pf, sf``: the fitted points (:func:`survival_fit_points`). P(τ0) is held; three starts (data-driven,
    and f_ne = P at τ0 + 0.85 (τ2 − τ0) with (L, b) = (1, 1) and (3, 0.3)), the best χ² kept
    (:func:`best_fit`). Units: t in time units, E in energy units, γ in 1/time.
    """
    check.curve(t, P)
    check.floats(P_err, "P_err", size=len(t), of="time t")
    check.curve(tf, Pf, ("tf", "Pf"))
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

    ``t, P``: the whole Kaplan–Meier curve (P(τ0) and the starting never-escaping fractions are read from it);
    ``tf, Pf, sf``: the fitted points (:func:`survival_fit_points`); ``comps`` the sub-ensembles
    (:func:`~hhscatter.analysis.dissipative.mixture.mixture_components`); ``kappa`` κ0(E) (1/time); ``mode``
    "shared" (one never-escaping share φ of P(τ0)) or "free" (one f_ne,k per sub-ensemble). P(τ0) is held; three
    starts (data-driven, and the never-escaping fraction P at τ0 + 0.85 (τ2,min − τ0) — shared, or handed to the
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
    >>> kappa = PiecewiseKappa(E_c=1 / 6, a2=13.63, a1=0.03, slope=1.41, E_switch=0.27)
    >>> fits = fit_mixture_hazards(t, P, tf, Pf, sf, comps, kappa=kappa, tau0=5.0,
    ...                            E_c=1 / 6, hazards=["paper"], mode="shared", P_min=1e-4)
    >>> sorted(fits), bool(np.isfinite(fits["paper"].chi2))
    (['paper'], True)
    """
    check.curve(t, P)
    check.curve(tf, Pf, ("tf", "Pf"))
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
    else:  # never-escaping orbits first assigned to the low-energy sub-ensembles (they reach E_c first)
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
