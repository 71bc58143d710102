"""Tables of the survival model against simulations (paper Fig. 6 = fig:model_data_comparison).

The survival model, Eq. (eqn:surv_prob_model), fitted to a simulated P(t) per (E0, γ) gives one row of
parameters per model and hazard (:func:`fit_row`) and its curves beside the data (:func:`model_rows`). The same
fit with the paper's constants — its κ0(E) of the Fig. 2b caption and μ = 0.91 — beside ours on the same
points gives :func:`constants_row` and :func:`constants_taus`. Panel (b): τ1 predicted by the model fitted to
the P(t) of paired ensembles against the observed τ1 (Eq. (eqn:tau1)), τ2 of Eq. (eq:tau2) against the first
settling time (:func:`tau_vs_gamma`, :func:`tau2_curve`).

Units: times in model time units, energies in model units, γ in 1/time, κ in 1/time.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.mixture import mixture_components
from hhscatter.analysis.dissipative.model_comparison import better_fit, compare_fits, predict_tau1
from hhscatter.analysis.dissipative.transitions import tau2_observed, tau2_predicted
from hhscatter.analysis.survival.fits import survival_from_lifetimes
from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
from hhscatter.reproduction.hazard_fits import fit_homogeneous_hazards, fit_mixture_hazards, survival_fit_points

__all__ = [
    "PAPER_CONSTANTS",
    "ModelInputs",
    "TauReference",
    "constants_record",
    "constants_row",
    "constants_taus",
    "fit_row",
    "kappa_from_constants",
    "mixture_fits",
    "model_rows",
    "number_or_none",
    "pair_fits",
    "survival_grid_curve",
    "tau2_curve",
    "tau2_reference",
    "tau_predictions",
    "tau_reference",
    "tau_vs_gamma",
    "value_and_err",
]

#: the name of the fits made with the paper's constants (columns, tables, a numbers-JSON key, ``better``)
PAPER_CONSTANTS = "paper_constants"


def kappa_from_constants(const: dict, E_c: float) -> PiecewiseKappa:
    """The piecewise κ0(E) of paper Fig. 2b (fig:kappa-E-dependence) with the coefficients ``const``.

    ``const`` holds a, b, c (κ0 = a x² + b x below E_b, c x from E_b on, x = E − E_c; a in 1/(time·energy²), b
    and c in 1/(time·energy)) and E_b (an energy); ``E_c`` is the system's critical energy.

    Examples
    --------
    >>> k = kappa_from_constants({"a": 13.63, "b": 0.03, "c": 1.41, "E_b": 0.27}, 1 / 6)
    >>> round(float(k(0.3)), 6)   # 1.41 · (0.3 − 1/6)
    0.188
    """
    return PiecewiseKappa(
        a2=float(const["a"]),
        a1=float(const["b"]),
        slope=float(const["c"]),
        E_switch=float(const["E_b"]),
        E_c=float(E_c),
    )


def survival_grid_curve(lifetimes: pd.DataFrame, dt: float):
    """(t, P, P_err): the Kaplan–Meier P(t) of ``lifetimes`` (t_end, outcome) on 0, dt, … past the last t_end.

    Examples
    --------
    >>> lt = pd.DataFrame({"t_end": [1.0, 2.0], "outcome": ["escaped", "escaped"]})
    >>> t, P, _ = survival_grid_curve(lt, 1.0)
    >>> t.tolist(), P.tolist()
    ([0.0, 1.0, 2.0], [1.0, 0.5, 0.0])
    """
    t_hi = float(lifetimes["t_end"].max())
    grid = np.arange(0.0, t_hi + dt, dt)
    c = survival_from_lifetimes(lifetimes, grid)
    return c.t, c.P, c.P_err


def _scalar_params(row: dict, fit, names) -> dict:
    v, e = fit.values, fit.errors
    for k in names:
        if k in v and np.ndim(v[k]) == 0:
            row[k] = float(v[k])
            row[f"{k}_err"] = float(e.get(k, math.nan)) if np.ndim(e.get(k, 0.0)) == 0 else math.nan
    return row


def fit_row(label: str, model: str, hazard: str, fit, extra: dict) -> dict:
    """One row of the fits table: goodness of fit and the scalar parameters of a fitted survival model.

    ``fit`` a :class:`~hhscatter.analysis.dissipative.survival_model.SurvivalFit` (or a mixture's); columns
    pair = ``label``, model, hazard, n_points, n_free, chi2, dof, chi2_red, rms_log_residual, aic, success, then
    ``extra``, then f_ne, f_e, L, b, tau2, phi, P_tau0 with their errors where the fit has them as scalars.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> fit = SimpleNamespace(values={"f_ne": 0.1, "L": 2.0}, errors={"f_ne": 0.01}, n_points=10, free=["f_ne", "L"],
    ...     chi2=8.0, dof=8, chi2_red=1.0, rms_log_residual=0.05, aic=12.0, success=True)
    >>> r = fit_row("E0.30_g0.01", "homogeneous", "paper", fit, {"gamma": 0.01})
    >>> r["n_free"], r["f_ne_err"], r["L_err"] != r["L_err"]
    (2, 0.01, True)
    """
    row = {
        "pair": label,
        "model": model,
        "hazard": hazard,
        "n_points": fit.n_points,
        "n_free": len(fit.free),
        "chi2": fit.chi2,
        "dof": fit.dof,
        "chi2_red": fit.chi2_red,
        "rms_log_residual": fit.rms_log_residual,
        "aic": fit.aic,
        "success": fit.success,
        **extra,
    }
    return _scalar_params(row, fit, ("f_ne", "f_e", "L", "b", "tau2", "phi", "P_tau0"))


def constants_row(ours, theirs, *, pair, E0, gamma, hazard, tau2_ours, tau2_pc) -> dict:
    """One (pair, hazard) row: the fit with the paper's constants (``theirs``) beside ours on the same points.

    Columns: pair, E0, gamma, hazard, n_points, rms_log_residual (+ _ours), better (the smaller RMS log residual
    by :func:`~hhscatter.analysis.dissipative.model_comparison.better_fit`: "ours", :data:`PAPER_CONSTANTS` or
    "tie"), chi2_red (+ _ours), aic (+ _ours), tau2_predicted (Eq. (eq:tau2) with the paper's μ, + _ours),
    success and the paper-constant fit's f_ne, f_e, L, b with their errors.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> def fit(rms): return SimpleNamespace(t_fit=[1.0, 2.0], rms_log_residual=rms, n_points=2, chi2_red=1.0,
    ...     aic=3.0, success=True, values={"f_ne": .1, "f_e": .5, "L": 1., "b": 1.}, errors={})
    >>> constants_row(fit(0.1), fit(0.2), pair="p", E0=0.3, gamma=0.01, hazard="paper", tau2_ours=80.0,
    ...               tau2_pc=79.0)["better"]
    'ours'
    """
    best = better_fit({"ours": ours, PAPER_CONSTANTS: theirs})
    row = {
        "pair": pair,
        "E0": E0,
        "gamma": gamma,
        "hazard": hazard,
        "n_points": theirs.n_points,
        "rms_log_residual": theirs.rms_log_residual,
        "rms_log_residual_ours": ours.rms_log_residual,
        "better": best if best is not None else "tie",
        "chi2_red": theirs.chi2_red,
        "chi2_red_ours": ours.chi2_red,
        "aic": theirs.aic,
        "aic_ours": ours.aic,
        "tau2_predicted": tau2_pc,
        "tau2_predicted_ours": tau2_ours,
        "success": theirs.success,
    }
    for k in ("f_ne", "f_e", "L", "b"):
        row[k] = float(theirs.values[k])
        row[f"{k}_err"] = float(theirs.errors.get(k, math.nan))
    return row


def model_rows(
    t, curve: pd.DataFrame, label: str, homog: dict, homog_pc: dict, mixes: dict, extra: dict, *, E_c, mu, mu_pc
):
    """(fit rows, compare rows, paper-constant rows) of one (E0, γ); the model curves added to ``curve``.

    ``homog`` and ``homog_pc`` {hazard: fit} of the homogeneous model with our constants and the paper's,
    ``mixes`` {mixture name: {hazard: fit}}; ``extra`` the pair's columns (E0, gamma, ...). For every hazard h
    the columns ``<model>_<h>`` and ``paper_constants_<h>`` of ``curve`` get the models at ``t``; the compare
    rows are :func:`~hhscatter.analysis.dissipative.model_comparison.compare_fits` of the homogeneous model and
    the mixtures; τ2 of Eq. (eq:tau2) with μ (ours) and ``mu_pc`` (the paper's).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> def fit(rms): return SimpleNamespace(t_fit=[1.0], rms_log_residual=rms, n_points=1, free=["L"], chi2=1.,
    ...     dof=1, chi2_red=1., aic=3., success=True, values={"f_ne": .1, "f_e": .5, "L": 1., "b": 1.}, errors={},
    ...     predict=lambda t: np.ones_like(t))
    >>> t = np.array([0.0, 1.0]); cur = pd.DataFrame({"t": t})
    >>> f, c, p = model_rows(t, cur, "x", {"paper": fit(.1)}, {"paper": fit(.2)}, {}, {"E0": .3, "gamma": .01},
    ...                      E_c=1 / 6, mu=0.9, mu_pc=0.91)
    >>> list(cur.columns), len(f), p[0]["better"]
    (['t', 'homogeneous_paper', 'paper_constants_paper'], 1, 'ours')
    """
    E0, g = extra["E0"], extra["gamma"]
    hazards = list(homog)
    fit_rows, cmp_rows, pc_rows = [], [], []
    for h in hazards:
        models = {"homogeneous": homog[h], **{name: m[h] for name, m in mixes.items()}}
        for name, f in models.items():
            fit_rows.append(fit_row(label, name, h, f, extra))
            curve[f"{name}_{h}"] = f.predict(t)
        cmp = compare_fits(models).reset_index()
        cmp_rows.append(cmp.assign(pair=label, E0=E0, gamma=g, hazard=h))
    for h in hazards:
        curve[f"{PAPER_CONSTANTS}_{h}"] = homog_pc[h].predict(t)
        pc_rows.append(
            constants_row(
                homog[h],
                homog_pc[h],
                pair=label,
                E0=E0,
                gamma=g,
                hazard=h,
                tau2_ours=tau2_predicted(E0, E_c, mu, g),
                tau2_pc=tau2_predicted(E0, E_c, mu_pc, g),
            )
        )
    return fit_rows, cmp_rows, pc_rows


class TauReference(NamedTuple):
    """Observed transition times of paired ensembles at one E0, for panel (b).

    ``obs``: DataFrame gamma, tau1_observed, tau1_err, tau2_observed, tau2_err (None where not observed);
    ``lifetimes``: {γ > 0: DataFrame(t_end, outcome)}; ``P_0``: (t, P) of the conservative curve, or None;
    ``E0``: their initial energy.
    """

    obs: pd.DataFrame
    lifetimes: dict
    P_0: tuple | None
    E0: float


def number_or_none(v):
    """A finite float, or None (a missing, non-numeric or non-finite value).

    Examples
    --------
    >>> number_or_none("2.5"), number_or_none(float("nan")), number_or_none(None)
    (2.5, None, None)
    """
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def value_and_err(v):
    """(value, err) of a numbers-JSON field: ``{"value", "err"}`` or a plain number (err None).

    Examples
    --------
    >>> from hhscatter.analysis.stats import Measured
    >>> value_and_err(Measured(3.0, 0.5).to_dict()), value_and_err(4)
    ((3.0, 0.5), (4.0, None))
    """
    if isinstance(v, dict):
        return number_or_none(v.get("value")), number_or_none(v.get("err"))
    return number_or_none(v), None


def tau_reference(rows, lifetimes: dict, *, E0: float, dt: float, fields=("gamma", "tau1", "tau2")) -> TauReference:
    """The observed transition times of paired ensembles and their lifetimes, as panel (b)'s :class:`TauReference`.

    ``rows``: the rows of a τ table (a list of dicts or a DataFrame) with the fields ``fields`` = (γ, τ1, τ2), the
    times as numbers-JSON leaves ``{"value", "err"}`` or plain numbers (:func:`value_and_err`); ``lifetimes``:
    {γ: DataFrame(t_end, outcome)} of the paired runs at initial energy ``E0``, γ = 0 among them (the
    conservative reference, whose Kaplan–Meier P(t) on a grid of step ``dt`` becomes ``P_0``:
    :func:`survival_grid_curve`). The runs of the table's γ > 0 are kept; a γ of the table without a run has no
    lifetimes. Times in model time units.

    Examples
    --------
    >>> from hhscatter.analysis.stats import Measured
    >>> rows = [{"gamma": 0.01, "tau1": Measured(120.0, 4.0).to_dict(), "tau2": 300.0}]
    >>> lt = pd.DataFrame({"t_end": [1.0, 2.0], "outcome": ["escaped", "escaped"]})
    >>> ref = tau_reference(rows, {0.0: lt, 0.01: lt, 0.02: lt}, E0=0.3, dt=1.0)
    >>> ref.obs.values.tolist(), sorted(ref.lifetimes), ref.P_0[1].tolist()
    ([[0.01, 120.0, 4.0, 300.0, None]], [0.01], [1.0, 0.5, 0.0])
    """
    gcol, t1, t2 = fields
    table = pd.DataFrame(rows)
    obs = pd.DataFrame(
        {
            "gamma": table[gcol].astype(float),
            "tau1_observed": [value_and_err(v)[0] for v in table[t1]],
            "tau1_err": [value_and_err(v)[1] for v in table[t1]],
            "tau2_observed": [value_and_err(v)[0] for v in table[t2]],
            "tau2_err": [value_and_err(v)[1] for v in table[t2]],
        }
    )
    t0c, P0c, _ = survival_grid_curve(lifetimes[0.0], dt)
    kept = {g: lifetimes[g] for g in obs["gamma"] if g > 0 and g in lifetimes}
    return TauReference(obs, kept, (t0c, P0c), E0)


def tau2_reference(lifetimes: dict, E0: float) -> TauReference:
    """Panel (b)'s :class:`TauReference` from dissipative runs alone: τ2 observed (:func:`~hhscatter.analysis.dissipative.transitions.tau2_observed`), no τ1.

    ``lifetimes``: {γ > 0: DataFrame(t_end, outcome)} of runs at initial energy ``E0``; without a conservative
    run there is no P_0 and no τ1 (their columns hold None). Times in model time units.

    Examples
    --------
    >>> lt = pd.DataFrame({"t_end": [5.0, 3.0, 9.0], "outcome": ["escaped", "settled", "settled"]})
    >>> ref = tau2_reference({0.01: lt}, 0.3)
    >>> ref.obs.to_dict(orient="records"), ref.P_0
    ([{'gamma': 0.01, 'tau1_observed': None, 'tau1_err': None, 'tau2_err': None, 'tau2_observed': 3.0}], None)
    """
    obs = pd.DataFrame(
        {
            "gamma": sorted(lifetimes),
            "tau1_observed": None,
            "tau1_err": None,
            "tau2_err": None,
            "tau2_observed": [tau2_observed(lifetimes[g]) for g in sorted(lifetimes)],
        }
    )
    return TauReference(obs, lifetimes, None, E0)


def tau_vs_gamma(ref: TauReference, *, kappa, mu, mu_err, tau0, E_c, hazards, dt, fit_dt, min_count, alpha):
    """Panel (b) with one set of constants (κ0(E), μ): observed τ1, τ2 beside the model's τ1 and Eq. (eq:tau2).

    Per γ > 0 of ``ref.obs``: τ2 predicted = ln(E0/E_c)/(μγ) (± its σ from ``mu_err``); where the lifetimes
    are there and give ≥ 5 fitted points (:func:`~hhscatter.reproduction.hazard_fits.survival_fit_points`
    on the Kaplan–Meier curve of step ``dt``, grid ``fit_dt``, N·P ≥ ``min_count``), the homogeneous model fitted
    in every hazard form and, with ``ref.P_0``, its τ1 (Eq. (eqn:tau1), P = α P_0, by
    :func:`~hhscatter.analysis.dissipative.model_comparison.predict_tau1`).

    Returns
    -------
    (DataFrame, dict)
        Columns gamma, tau1_observed (+ _err), tau2_observed (+ _err), tau2_predicted (+ _err),
        tau1_pred_<h>, f_ne_<h>, rms_<h>; and {γ: {hazard: SurvivalFit}}.

    Examples
    --------
    >>> ref = TauReference(pd.DataFrame({"gamma": [0.01], "tau1_observed": [None], "tau1_err": [None],
    ...     "tau2_observed": [80.0], "tau2_err": [None]}), {}, None, 0.3)
    >>> tab, fits = tau_vs_gamma(ref, kappa=None, mu=0.9, mu_err=0.09, tau0=5.0, E_c=1 / 6, hazards=["paper"],
    ...     dt=0.5, fit_dt=2.0, min_count=20, alpha=2.0)
    >>> round(float(tab["tau2_predicted"][0]), 2), round(float(tab["tau2_predicted_err"][0]), 3), fits
    (65.31, 6.531, {})
    """
    rows, fits_by_gamma = [], {}
    for r in ref.obs[ref.obs["gamma"] > 0].sort_values("gamma").itertuples():
        g = float(r.gamma)
        tau2_pred = tau2_predicted(ref.E0, E_c, mu, g)
        row = {
            "gamma": g,
            "tau1_observed": number_or_none(r.tau1_observed),
            "tau1_observed_err": number_or_none(r.tau1_err),
            "tau2_observed": number_or_none(r.tau2_observed),
            "tau2_observed_err": number_or_none(r.tau2_err),
            "tau2_predicted": tau2_pred,
            "tau2_predicted_err": tau2_pred * mu_err / mu if math.isfinite(mu_err) else math.nan,
        }
        lt = ref.lifetimes.get(g)
        for h in hazards:
            row[f"tau1_pred_{h}"] = None
            row[f"f_ne_{h}"] = None
        if lt is not None:
            t, P, P_err = survival_grid_curve(lt, dt)
            tf, Pf, sf = survival_fit_points(t, P, P_err, tau0, fit_dt, len(lt), min_count)
            if tf.size >= 5:
                fits = fit_homogeneous_hazards(
                    t,
                    P,
                    P_err,
                    tf,
                    Pf,
                    sf,
                    kappa=kappa,
                    E0=ref.E0,
                    mu=mu,
                    gamma=g,
                    tau0=tau0,
                    E_c=E_c,
                    hazards=hazards,
                    fit_tau2=False,
                    P_min=min_count / len(lt) * 0.999,
                )
                fits_by_gamma[g] = fits
                for h in hazards:
                    row[f"f_ne_{h}"] = float(fits[h].values["f_ne"])
                    row[f"rms_{h}"] = float(fits[h].rms_log_residual)
                    if ref.P_0 is not None:
                        row[f"tau1_pred_{h}"] = predict_tau1(fits[h], ref.P_0, alpha)
        rows.append(row)
    return pd.DataFrame(rows), fits_by_gamma


def constants_taus(ours: pd.DataFrame, theirs: pd.DataFrame, fits_ours: dict, fits_pc: dict, hazards) -> pd.DataFrame:
    """Per γ: τ1 and τ2 predicted with the paper's constants beside ours (suffix ``_ours``) and the observed ones.

    ``ours``, ``theirs``: :func:`tau_vs_gamma` tables with our constants and the paper's (the same γ, else
    RuntimeError); ``fits_ours``, ``fits_pc``: their fits {γ: {hazard: fit}}. Per hazard h: tau1_pred_h (+ _ours),
    rms_h (+ _ours) and better_h (:func:`~hhscatter.analysis.dissipative.model_comparison.better_fit`, "tie" on
    equal RMS, None where a γ has no fit).

    Examples
    --------
    >>> t = pd.DataFrame({"gamma": [0.01], "tau1_observed": [None], "tau2_observed": [80.0],
    ...                   "tau2_predicted": [65.0], "tau1_pred_paper": [None]})
    >>> constants_taus(t, t.assign(tau2_predicted=64.0), {}, {}, ["paper"])[["tau2_predicted", "better_paper"]]
       tau2_predicted better_paper
    0            64.0         None
    """
    if list(ours["gamma"]) != list(theirs["gamma"]):
        raise RuntimeError("τ tables of our and the paper's constants cover different γ")  # same fig4 table
    rows = []
    for o, p in zip(ours.to_dict("records"), theirs.to_dict("records")):
        g = o["gamma"]
        row = {
            "gamma": g,
            "tau1_observed": o["tau1_observed"],
            "tau2_observed": o["tau2_observed"],
            "tau2_predicted": p["tau2_predicted"],
            "tau2_predicted_ours": o["tau2_predicted"],
        }
        for h in hazards:
            row[f"tau1_pred_{h}"] = p[f"tau1_pred_{h}"]
            row[f"tau1_pred_{h}_ours"] = o[f"tau1_pred_{h}"]
            both = g in fits_ours and g in fits_pc
            row[f"rms_{h}"] = float(fits_pc[g][h].rms_log_residual) if both else None
            row[f"rms_{h}_ours"] = float(fits_ours[g][h].rms_log_residual) if both else None
            best = better_fit({"ours": fits_ours[g][h], PAPER_CONSTANTS: fits_pc[g][h]}) if both else None
            row[f"better_{h}"] = (best or "tie") if both else None
        rows.append(row)
    return pd.DataFrame(rows)


def tau2_curve(taus: pd.DataFrame, E0: float, E_c: float, mu: float, mu_err: float, mu_pc: float) -> pd.DataFrame:
    """Eq. (eq:tau2), τ2 = ln(E0/E_c)/(μγ), on 200 log-spaced γ around those of ``taus``: with our μ, its ±1σ
    band (τ2 / (1 ± σ_μ/μ)) and with the paper's μ (column ``tau2_predicted_paper_constants``).

    Examples
    --------
    >>> c = tau2_curve(pd.DataFrame({"gamma": [0.01]}), 0.3, 1 / 6, 0.9, 0.09, 0.91)
    >>> len(c), round(float(c["gamma"].iloc[0]), 6), bool((c["tau2_lo"] < c["tau2_predicted"]).all())
    (200, 0.0008, True)
    """
    gg = (
        np.geomspace(min(taus["gamma"].min(), 1e-3) * 0.8, max(taus["gamma"].max(), 0.02) * 1.25, 200)
        if len(taus)
        else np.geomspace(1e-3, 0.03, 200)
    )
    t2 = tau2_predicted(E0, E_c, mu, gg)
    return pd.DataFrame(
        {
            "gamma": gg,
            "tau2_predicted": t2,
            "tau2_lo": t2 / (1 + mu_err / mu) if math.isfinite(mu_err) else t2,
            "tau2_hi": t2 / (1 - mu_err / mu) if math.isfinite(mu_err) else t2,
            f"tau2_predicted_{PAPER_CONSTANTS}": tau2_predicted(E0, E_c, mu_pc, gg),
        }
    )


def constants_record(pc: dict, E_c: float, tau0: float, pcf: pd.DataFrame, pct: pd.DataFrame, hazards) -> dict:
    """The numbers-JSON record of the fits with the paper's constants ``pc`` (a, b, c, E_b, μ).

    ``constants`` (with E_c and their source), ``tau0``, ``method``, ``fits`` (the rows of :func:`constants_row`)
    and ``tau_vs_gamma`` (the rows of :func:`constants_taus`).

    Examples
    --------
    >>> rec = constants_record({"a": 13.63, "b": 0.03, "c": 1.41, "E_b": 0.27, "mu": 0.91}, 1 / 6, 5.0,
    ...                        pd.DataFrame(), pd.DataFrame(), ["paper"])
    >>> rec["constants"]["mu"], rec["fits"], "hazard forms paper" in rec["method"]
    (0.91, [], True)
    """
    return {
        "constants": {
            **pc,
            "E_c": E_c,
            "source": "study.toml [study] paper_kappa_a, paper_kappa_b, paper_kappa_c, paper_kappa_Eb, "
            "paper_mu (paper: Fig. 2b caption; Sec. III.A, Fig. 3)",
        },
        "tau0": tau0,
        "method": (
            "the homogeneous model, Eq. (eqn:surv_prob_model), in hazard forms "
            f"{', '.join(hazards)}, with κ0(E) and μ held at these values; free f_ne, L, b "
            "(f_e = P(τ0) − f_ne) fitted on the same points as with our constants; τ0 ours (fig4): "
            "the paper gives none; 'better': the smaller rms log residual (columns '_ours': our "
            "constants)"
        ),
        "fits": pcf.to_dict(orient="records"),
        "tau_vs_gamma": pct.to_dict(orient="records"),
    }


class ModelInputs(NamedTuple):
    """What every fit of the survival model shares: the constants, the hazard forms and the mixture variants.

    ``inputs``: where each constant came from ({name: {"source": ...}}); ``kappa``: κ0(E) (1/time); ``mu``,
    ``mu_err``: the energy-decay exponent and its 1σ (dimensionless, NaN: unknown); ``tau0``: the start of the
    fits (time); ``E_c``: the critical energy; ``pc``: the paper's constants (a, b, c, E_b, mu) and ``kappa_pc``
    their κ0(E); ``hazards``: the hazard forms ("paper", "integrated"); ``mixtures``: the mixture variants, dicts
    with name, by ("energy" or "rate"), t_ref ("tau0" or a time) and fne_mode ("shared" or "free").
    """

    inputs: dict
    kappa: PiecewiseKappa
    mu: float
    mu_err: float
    tau0: float
    E_c: float
    pc: dict
    kappa_pc: PiecewiseKappa
    hazards: list
    mixtures: list


def mixture_fits(snapshots: pd.DataFrame, points, s: ModelInputs, *, label, E0, gamma, n_components, fit_end, P_min):
    """The mixture-model fits of one (E0, γ): sub-ensembles from the energy snapshots per mixture variant.

    ``snapshots``: the run's energy snapshots (traj_id, t, E) from τ0 on; ``points``: (t, P) of the Kaplan–Meier
    curve and (tf, Pf, sf) its fitted points (:func:`survival_fit_points`); per variant of ``s.mixtures``,
    ``n_components`` sub-ensembles at t_ref (:func:`~hhscatter.analysis.dissipative.mixture.mixture_components`,
    μ_i fitted on [τ0, ``fit_end``]) and the mixture model fitted in every hazard form
    (:func:`~hhscatter.reproduction.hazard_fits.fit_mixture_hazards`).

    Returns
    -------
    (list of DataFrame, dict)
        The components of each variant (columns of ``MixtureComponents.to_frame`` plus pair, E0, gamma, model),
        and {variant name: {hazard: SurvivalFit}}.
    """
    t, P, tf, Pf, sf = points
    comp_rows, mixes = [], {}
    for var in s.mixtures:
        t_ref = s.tau0 if var["t_ref"] == "tau0" else float(var["t_ref"])
        comps = mixture_components(
            snapshots, gamma=gamma, t_ref=t_ref, n_components=n_components, by=var["by"], fit_window=(s.tau0, fit_end)
        )
        comp_rows.append(comps.to_frame(s.E_c).assign(pair=label, E0=E0, gamma=gamma, model=var["name"]))
        mixes[var["name"]] = fit_mixture_hazards(
            t,
            P,
            tf,
            Pf,
            sf,
            comps,
            kappa=s.kappa,
            tau0=s.tau0,
            E_c=s.E_c,
            hazards=s.hazards,
            mode=var["fne_mode"],
            P_min=P_min,
        )
    return comp_rows, mixes


def pair_fits(
    lifetimes: pd.DataFrame, snapshots, s: ModelInputs, *, label, E0, gamma, dt, fit_dt, min_count, fit_tau2, **mix
):
    """One (E0, γ): its Kaplan–Meier P(t), the homogeneous model with our constants and the paper's, the mixtures.

    ``lifetimes``: DataFrame t_end, outcome of the run (N orbits); ``snapshots``: its energy snapshots from τ0 on,
    or a function returning them (read only once the homogeneous fits are done); P(t) on a grid of step ``dt``,
    fitted on points ``fit_dt`` apart from τ0 with N·P ≥ ``min_count``
    (:func:`~hhscatter.reproduction.hazard_fits.fit_homogeneous_hazards`, τ2 free if ``fit_tau2``);
    ``mix``: ``n_components`` and ``fit_end`` of :func:`mixture_fits`.

    Returns
    -------
    (DataFrame, tuple)
        The curve (t, P, P_err, the model columns of :func:`model_rows`, pair, E0, gamma, N) and (fit rows,
        component frames, compare frames, paper-constant rows).
    """
    n = len(lifetimes)
    t, P, P_err = survival_grid_curve(lifetimes, dt)
    tf, Pf, sf = survival_fit_points(t, P, P_err, s.tau0, fit_dt, n, min_count)
    P_min = min_count / n * 0.999
    common = dict(E0=E0, gamma=gamma, tau0=s.tau0, E_c=s.E_c, hazards=s.hazards, fit_tau2=fit_tau2, P_min=P_min)
    homog = fit_homogeneous_hazards(t, P, P_err, tf, Pf, sf, kappa=s.kappa, mu=s.mu, **common)
    # the same fit with the paper's κ0(E) and μ held instead of ours: same points, starts and free parameters,
    # so the two RMS log residuals compare the constants alone
    homog_pc = fit_homogeneous_hazards(t, P, P_err, tf, Pf, sf, kappa=s.kappa_pc, mu=s.pc["mu"], **common)
    snaps = snapshots() if callable(snapshots) else snapshots
    comp_rows, mixes = mixture_fits(snaps, (t, P, tf, Pf, sf), s, label=label, E0=E0, gamma=gamma, P_min=P_min, **mix)
    del snaps
    extra = {
        "E0": E0,
        "gamma": gamma,
        "N": n,
        "tau2_eq": tau2_predicted(E0, s.E_c, s.mu, gamma),
        "tau2_observed": tau2_observed(lifetimes),
    }
    cur = pd.DataFrame({"t": t, "P": P, "P_err": P_err})
    fit_rows, cmp_rows, pc_rows = model_rows(
        t, cur, label, homog, homog_pc, mixes, extra, E_c=s.E_c, mu=s.mu, mu_pc=s.pc["mu"]
    )
    return cur.assign(pair=label, E0=E0, gamma=gamma, N=n), (fit_rows, comp_rows, cmp_rows, pc_rows)


def tau_predictions(ref: TauReference, s: ModelInputs, *, dt, fit_dt, min_count, alpha):
    """Panel (b): τ1, τ2 against γ at ``ref.E0`` with our constants and with the paper's.

    :func:`tau_vs_gamma` with each set of constants (the paper's μ without an error), the comparison of the two
    (:func:`constants_taus`) and the τ2 band of Eq. (eq:tau2) (:func:`tau2_curve`).

    Returns
    -------
    (DataFrame, DataFrame, DataFrame)
        τ vs γ with our constants, the τ2 curve, the paper's constants beside ours.

    Examples
    --------
    >>> ref = TauReference(pd.DataFrame({"gamma": [0.01], "tau1_observed": [None], "tau1_err": [None],
    ...     "tau2_observed": [80.0], "tau2_err": [None]}), {}, None, 0.3)
    >>> s = ModelInputs({}, None, 0.9, 0.09, 5.0, 1 / 6, {"mu": 0.91}, None, ["paper"], [])
    >>> taus, curve, pct = tau_predictions(ref, s, dt=0.5, fit_dt=2.0, min_count=20, alpha=2.0)
    >>> round(float(taus["tau2_predicted"][0]), 2), round(float(pct["tau2_predicted"][0]), 2)
    (65.31, 64.59)
    """
    kw = {"tau0": s.tau0, "E_c": s.E_c, "hazards": s.hazards, "dt": dt, "fit_dt": fit_dt, "min_count": min_count}
    taus, fits = tau_vs_gamma(ref, kappa=s.kappa, mu=s.mu, mu_err=s.mu_err, alpha=alpha, **kw)
    taus_pc, fits_pc = tau_vs_gamma(ref, kappa=s.kappa_pc, mu=s.pc["mu"], mu_err=math.nan, alpha=alpha, **kw)
    pct = constants_taus(taus, taus_pc, fits, fits_pc, s.hazards)
    curve = tau2_curve(taus, ref.E0, s.E_c, s.mu, s.mu_err, s.pc["mu"])
    return taus, curve, pct
