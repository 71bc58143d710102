"""Study fig6: the survival model against simulations (paper Fig. 6, fig:model_data_comparison).

Paper (Sec. III.B.3): with κ_γ(t) = κ0(E(t)), κ0(E) the conservative escape
rate of Fig. 2b and E(t) = E0 e^{−μγt} of Fig. 3, Eq. (eqn:surv_prob_model)

    P_γ(t) = f_ne + f_e exp(−κ_γ(t)(t − τ0))        τ0 ≤ t ≤ τ2
           = f_ne exp(−g(t, γ)(t − τ2))             t > τ2,   g = L/(1 + e^{−b(t−τ2)})²,

with f_ne + f_e = P(τ0) and τ2 = ln(E0/E_c)/(μγ), Eq. (eq:tau2).  (a) the model
against simulated P(t) for several (E0, γ); (b) τ1 (Eq. (eqn:tau1), α = 2)
and τ2 predicted vs observed as functions of γ at E0 = 0.3.  The paper notes
that "a mixture model for P(t) involving multiple sub-ensembles, each with
their own energy decay exponent μ" should improve the agreement.

Stages
------
simulate   one run per (E0, γ) in ``pairs`` with energy snapshots (raw keys
           ``E<E0>_g<γ>``).
analyze    inputs (the studies of ``[needs]``, their published outputs only):
           κ0(E) (fig2.json), μ (fig3.json), τ0 and the observed τ table
           (fig4.json) and fig4's lifetimes at E0 = 0.3 (its derived table).  Per pair:
           Kaplan–Meier P(t); fits of the homogeneous model with the paper's
           literal escape factor (hazard "paper") and with the cumulative
           hazard exp(−∫κ0) ("integrated") — free f_ne, L, b; f_e = P(τ0) − f_ne;
           τ2 from Eq. (eq:tau2) —, and of the mixture model with the same
           number of free parameters (K energy quantiles at t_ref = τ0,
           per-orbit μ_i from the snapshots, one shared trapped fraction φ).
           For fig4's γ values: the homogeneous fit and the model's τ1
           (:func:`hhscatter.analysis.survival_model.predict_tau1` against fig4's γ = 0
           curve), τ2 = ln(E0/E_c)/(μγ).  Writes derived tables and fig6.json.
plot       Fig. 6 from the derived tables.

Errors: the fit errors treat the points of one Kaplan–Meier curve as
independent (``absolute_sigma``); the points are positively correlated, so
χ²/dof and the parameter errors are indicative (coarse grid ``fit_dt``).
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis import mixture
from hhscatter.analysis import survival_model as sm
from hhscatter.analysis.kappa_law import PiecewiseKappa
from hhscatter.analysis.survival import survival_from_lifetimes
from hhscatter.analysis.transitions import tau2_observed, tau2_predicted
from hhscatter.config import (
    Bool,
    Integer,
    Number,
    NumberLists,
    NumberOr,
    Numbers,
    OneOf,
    StudyParams,
    Text,
    Texts,
)
from hhscatter.studies import _upstream as up


class Mixture(StudyParams):
    """One entry of ``[study] mixtures``."""

    name: Text
    by: OneOf("energy", "rate")
    t_ref: NumberOr("tau0")
    fne_mode: OneOf("shared", "free")


class Params(StudyParams):
    """``[study]`` of studies/fig6/study.toml."""

    pairs: NumberLists           # [[E0, γ], ...]
    dt: Number
    fit_dt: Number
    min_count: Number
    hazards: Texts
    fit_tau2: Bool = False
    n_components: Integer
    mixtures: list[Mixture]
    mixture_fit_window: Numbers
    mixture_plotted: Text = None
    alpha: Number
    kappa_a_key: Text
    kappa_b_key: Text
    kappa_c_key: Text
    kappa_Eb_key: Text
    mu_key: Text
    tau0_key: Text
    tau_table_key: Text
    tau_gamma_field: Text
    tau1_field: Text
    tau2_field: Text
    fig4_E0: Number


PAPER_KAPPA = {"a": 13.63, "b": 0.03, "c": 1.41, "E_b": 0.27}
PAPER_MU = 0.91
DEV_TAU0 = 5.0  # development fallback only (the paper gives no number for τ0)


def pair_key(E0: float, g: float) -> str:
    """pair_key(E0, γ) -> raw run key, e.g. 'E0.30_g0.01'."""
    return f"E{E0:.2f}_g{g:g}"


def _pairs(study):
    out = []
    for p in study.param("pairs"):
        if len(p) != 2:
            raise ValueError(f"[study] pairs must hold [E0, gamma] pairs, got {p!r}")
        out.append((float(p[0]), float(p[1])))
    return out


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None; one run per (E0, γ) pair with energy snapshots."""
    for E0, g in _pairs(study):
        study.run(pair_key(E0, g), study.scene(pair_key(E0, g), energy=E0, gamma=g), workers=workers,
                  progress=progress)


# ---------------------------------------------------------------------------
# analysis helpers
# ---------------------------------------------------------------------------
def _inputs(study):
    inputs = {}
    ks = study.upstream("kappa")
    kv = {}
    for name in ("a", "b", "c", "E_b"):
        key = study.param("kappa_Eb_key" if name == "E_b" else f"kappa_{name}_key")
        kv[name], _ = up.value_or_fallback(study, ks, key, PAPER_KAPPA[name], inputs, f"kappa_{name}")
    E_c = study.model.critical_energy  # E_c = ω⁶/(6λ²) of the scene's model
    kappa = PiecewiseKappa(a2=float(kv["a"]), a1=float(kv["b"]), slope=float(kv["c"]),
                               E_switch=float(kv["E_b"]), E_c=E_c)
    mu, mu_err = up.value_or_fallback(study, study.upstream("mu"), study.param("mu_key"), PAPER_MU, inputs, "mu")
    tau0, _ = up.value_or_fallback(study, study.upstream("tau"), study.param("tau0_key"), DEV_TAU0, inputs, "tau0")
    return inputs, kappa, float(mu), float(mu_err if mu_err is not None else math.nan), float(tau0), E_c


def _curve(lifetimes, dt):
    t_hi = float(lifetimes["t_end"].max())
    grid = np.arange(0.0, t_hi + dt, dt)
    c = survival_from_lifetimes(lifetimes, grid)
    return c.t, c.P, c.P_err


def _fit_points(t, P, P_err, tau0, fit_dt, n, min_count):
    grid = np.arange(tau0, t[-1] + 1e-9, fit_dt)
    idx = np.clip(np.searchsorted(t, grid), 0, t.size - 1)
    idx = np.unique(idx)
    sel = (P[idx] * n >= min_count) & (P_err[idx] > 0)
    return t[idx][sel], P[idx][sel], P_err[idx][sel]


def _fit_row(label, model, hazard, fit, extra):
    v, e = fit.values, fit.errors
    row = {"pair": label, "model": model, "hazard": hazard,
           "n_points": fit.n_points, "n_free": len(fit.free), "chi2": fit.chi2, "dof": fit.dof,
           "chi2_red": fit.chi2_red, "rms_log_residual": fit.rms_log_residual, "aic": fit.aic,
           "success": fit.success, **extra}
    for k in ("f_ne", "f_e", "L", "b", "tau2", "phi", "P_tau0"):
        if k in v and np.ndim(v[k]) == 0:
            row[k] = float(v[k])
            row[f"{k}_err"] = float(e.get(k, math.nan)) if np.ndim(e.get(k, 0.0)) == 0 else math.nan
    return row


def _best(fit_fn, starts):
    """The fit with the smallest χ² over several starting-value dicts (the χ² surface has local minima:
    the settling branch can be traded for a lower trapped fraction)."""
    best = None
    for p0 in starts:
        try:
            f = fit_fn(p0)
        except (RuntimeError, ValueError):
            continue
        if best is None or f.chi2 < best.chi2:
            best = f
    if best is None:
        raise RuntimeError("survival-model fit failed from every starting point")
    return best


def _plateau(t, P, t_q):
    """P at time t_q (log-linear interpolation): the trapped fraction before settling starts."""
    return float(np.exp(np.interp(t_q, t, np.log(np.maximum(P, 1e-300)))))


def _homogeneous_fits(t, P, P_err, tf, Pf, sf, *, kappa, E0, mu, gamma, tau0, E_c, hazards, fit_tau2, P_min):
    P_tau0 = _plateau(t, P, tau0)
    tau2 = tau2_predicted(E0, E_c, mu, gamma)
    fne = min(_plateau(t, P, tau0 + 0.85 * (tau2 - tau0)), 0.95 * P_tau0)
    starts = [None, {"f_ne": fne, "L": 1.0, "b": 1.0}, {"f_ne": fne, "L": 3.0, "b": 0.3}]
    fits = {}
    for h in hazards:
        fits[h] = _best(lambda p0, h=h: sm.fit_survival_model(
            tf, Pf, sf, kappa_of_E=kappa, E0=E0, mu=mu, gamma=gamma, tau0=tau0, E_c=E_c, hazard=h,
            fit_tau2=fit_tau2, P_min=P_min, P_tau0=P_tau0, p0=p0), starts)
    return fits


def _mixture_variants(study):
    """The [study] mixtures list: dicts with name, by ("energy"/"rate"), t_ref ("tau0" or a time), fne_mode."""
    out = []
    for v in study.param("mixtures"):
        missing = {"name", "by", "t_ref", "fne_mode"} - set(v)
        if missing:
            raise ValueError(f"[study] mixtures entries need {sorted(missing)}: {v!r}")
        if not str(v["name"]).startswith("mixture"):
            raise ValueError(f"[study] mixtures names must start with 'mixture', got {v['name']!r}")
        out.append(dict(v))
    return out


def _mixture_fits(t, P, tf, Pf, sf, comps, *, kappa, tau0, E_c, hazards, mode, P_min):
    P_tau0 = _plateau(t, P, tau0)
    t2 = float(np.min(comps.tau2(E_c)))
    fne = min(_plateau(t, P, tau0 + 0.85 * max(t2 - tau0, 0.0)), 0.95 * P_tau0)
    if mode == "shared":
        alt = {"phi": fne / P_tau0}
    else:  # trapped orbits first assigned to the low-energy sub-ensembles (they reach E_c first)
        alt, left = {}, fne
        for k in np.argsort(comps.E_ref):
            cap = 0.99 * comps.weights[k] * P_tau0
            alt[f"f_ne_{k}"] = max(min(left, cap), 1e-9)
            left -= min(left, cap)
    starts = [None, {**alt, "L": 1.0, "b": 1.0}, {**alt, "L": 3.0, "b": 0.3}]
    return {h: _best(lambda p0, h=h: mixture.fit_mixture_model(
        tf, Pf, sf, comps, kappa_of_E=kappa, tau0=tau0, E_c=E_c, P_tau0=P_tau0, fne_mode=mode, hazard=h,
        P_min=P_min, p0=p0), starts) for h in hazards}


def analyze(study):
    """analyze(study) -> None; model fits, τ predictions, derived tables and fig6.json."""
    import pyarrow.dataset as pads

    from hhscatter.tables import read_lifetimes, read_snapshots

    inputs, kappa, mu, mu_err, tau0, E_c = _inputs(study)
    hazards = list(study.param("hazards"))
    dt, fit_dt = float(study.param("dt")), float(study.param("fit_dt"))
    min_count = float(study.param("min_count"))
    fit_tau2 = bool(study.param("fit_tau2"))
    K = int(study.param("n_components"))
    mixtures = _mixture_variants(study)
    w_hi = float(study.param("mixture_fit_window")[1])

    curves, fit_rows, comp_rows, cmp_rows = [], [], [], []
    for E0, g in _pairs(study):
        label = pair_key(E0, g)
        raw = study.raw(label)
        lt = read_lifetimes(raw, columns=["traj_id", "t_end", "outcome", "e0", "gamma"])
        n = len(lt)
        t, P, P_err = _curve(lt, dt)
        tf, Pf, sf = _fit_points(t, P, P_err, tau0, fit_dt, n, min_count)
        P_min = min_count / n * 0.999
        homog = _homogeneous_fits(t, P, P_err, tf, Pf, sf, kappa=kappa, E0=E0, mu=mu, gamma=g, tau0=tau0, E_c=E_c,
                                  hazards=hazards, fit_tau2=fit_tau2, P_min=P_min)
        snaps = read_snapshots(raw, filters=pads.field("t") >= tau0)
        mixes = {}
        for var in mixtures:
            t_ref = tau0 if var["t_ref"] == "tau0" else float(var["t_ref"])
            comps = mixture.mixture_components(snaps, gamma=g, t_ref=t_ref, n_components=K, by=var["by"],
                                           fit_window=(tau0, w_hi))
            comp_rows.append(comps.to_frame().assign(pair=label, E0=E0, gamma=g, model=var["name"]))
            mixes[var["name"]] = _mixture_fits(t, P, tf, Pf, sf, comps, kappa=kappa, tau0=tau0, E_c=E_c,
                                               hazards=hazards, mode=var["fne_mode"], P_min=P_min)
        extra = {"E0": E0, "gamma": g, "N": n, "tau2_eq": tau2_predicted(E0, E_c, mu, g),
                 "tau2_observed": tau2_observed(lt)}
        cur = pd.DataFrame({"t": t, "P": P, "P_err": P_err})
        for h in hazards:
            models = {"homogeneous": homog[h], **{name: m[h] for name, m in mixes.items()}}
            for name, f in models.items():
                fit_rows.append(_fit_row(label, name, h, f, extra))
                cur[f"{name}_{h}"] = f.predict(t)
            cmp = sm.compare_fits(models).reset_index()
            cmp_rows.append(cmp.assign(pair=label, E0=E0, gamma=g, hazard=h))
        curves.append(cur.assign(pair=label, E0=E0, gamma=g, N=n))
    curves = pd.concat(curves, ignore_index=True)
    fits = pd.DataFrame(fit_rows)
    comps = pd.concat(comp_rows, ignore_index=True)
    cmps = pd.concat(cmp_rows, ignore_index=True)

    taus, tau_curves = _tau_vs_gamma(study, inputs, kappa=kappa, mu=mu, mu_err=mu_err, tau0=tau0, E_c=E_c,
                                     hazards=hazards, dt=dt, fit_dt=fit_dt, min_count=min_count)

    study.write_table(curves, "curves.parquet", tau0=tau0, mu=mu)
    study.write_table(fits, "fits.parquet")
    study.write_table(comps, "mixture_components.parquet")
    study.write_table(cmps, "compare_fits.parquet")
    study.write_table(taus, "tau_vs_gamma.parquet")
    study.write_table(tau_curves, "tau2_curve.parquet")

    # -- paper comparison --------------------------------------------------------
    study.compare("μ used (from fig3)", mu, mu_err, PAPER_MU, note=inputs["mu"]["source"])
    for r in fits.itertuples():
        if r.model == "homogeneous":
            study.compare(f"Fig. 6a {r.pair}: homogeneous ({r.hazard}) rms log residual", r.rms_log_residual, None,
                          None, verdict=None,
                          note=f"χ²/dof = {r.chi2_red:.3g} ({r.n_points} points); paper: 'satisfying agreement'")
    for h in hazards:
        c = cmps[cmps["hazard"] == h].pivot(index="pair", columns="model", values="rms_log_residual")
        a = cmps[cmps["hazard"] == h].pivot(index="pair", columns="model", values="aic")
        for var in mixtures:
            name, mode = var["name"], var["fne_mode"]
            better = int((c[name] < c["homogeneous"]).sum())
            better_aic = int((a[name] < a["homogeneous"]).sum())
            study.compare(f"{name} vs homogeneous ({h} hazard): pairs with smaller rms log residual (AIC)",
                          f"{better} ({better_aic}) of {len(c)}", None, "improved agreement expected (future work)",
                          verdict="agrees" if better > len(c) / 2 else "differs",
                          note=(f"components by {var['by']} at t_ref = {var['t_ref']}; same data selection; "
                                + ("same number of free parameters (one trapped fraction φ)"
                                if mode == "shared" else "K trapped fractions f_ne,k: K − 1 more parameters")
                                + "; rms " + ", ".join(f"{p}: {c.loc[p, 'homogeneous']:.3f} → {c.loc[p, name]:.3f}"
                                                       for p in c.index)))
    for r in taus.itertuples():
        if r.tau2_observed is not None and np.isfinite(r.tau2_observed):
            rel = (r.tau2_observed - r.tau2_predicted) / r.tau2_predicted
            study.compare(f"τ2(γ={r.gamma:g}) observed vs Eq. (eq:tau2)", r.tau2_observed, None,
                          None, verdict=f"{100 * rel:+.0f}% from predicted {r.tau2_predicted:.1f}",
                          note="observed: first settling time (fig4); paper: τ2 ∝ 1/γ, predicted by Eq. (eq:tau2)")
        for h in hazards:
            pred = getattr(r, f"tau1_pred_{h}")
            if r.tau1_observed is not None and np.isfinite(r.tau1_observed) and pred is not None and np.isfinite(pred):
                study.compare(f"τ1(γ={r.gamma:g}) observed vs model ({h})", r.tau1_observed, None, None,
                              verdict=f"model {pred:.1f} ({100 * (pred - r.tau1_observed) / r.tau1_observed:+.0f}%)",
                              note="observed from fig4 (Eq. (eqn:tau1), α = 2); model: fitted Eq. (eqn:surv_prob_model)")

    study.write_numbers({
        "inputs": inputs,
        "dev_fallback": up.any_fallback(inputs),
        "kappa0": {"a": kappa.a2, "b": kappa.a1, "c": kappa.slope, "E_b": kappa.E_switch, "E_c": E_c},
        "mu": {"value": mu, "err": mu_err},
        "tau0": tau0,
        "fits": fits.to_dict(orient="records"),
        "compare_fits": cmps.to_dict(orient="records"),
        "mixture_components": comps.to_dict(orient="records"),
        "tau_vs_gamma": taus.to_dict(orient="records"),
    })


def _tau_vs_gamma(study, inputs, *, kappa, mu, mu_err, tau0, E_c, hazards, dt, fit_dt, min_count):
    """Panel (b): observed τ1, τ2 from fig4's table; model τ1 from fits to fig4's P(t); τ2 from Eq. (eq:tau2)."""
    from hhscatter.tables import read_lifetimes

    E0 = float(study.param("fig4_E0"))
    other = study.upstream("tau")
    try:
        doc = up.numbers(study, other)
        table, _ = up.lookup(doc, study.param("tau_table_key"), what=f"{other}.json")
        obs = pd.DataFrame(table)
        gcol, t1, t2 = (study.param(k) for k in ("tau_gamma_field", "tau1_field", "tau2_field"))
        missing = {gcol, t1, t2} - set(obs.columns)
        if missing:
            raise up.UpstreamError(f"{other}.json:{study.param('tau_table_key')} rows lack {sorted(missing)}; "
                                   f"have {sorted(obs.columns)}")
        obs = pd.DataFrame({"gamma": obs[gcol].astype(float),
                            "tau1_observed": [_val(v)[0] for v in obs[t1]], "tau1_err": [_val(v)[1] for v in obs[t1]],
                            "tau2_observed": [_val(v)[0] for v in obs[t2]], "tau2_err": [_val(v)[1] for v in obs[t2]]})
        inputs["tau_table"] = {"source": f"{other}.json:{study.param('tau_table_key')}"}
        # P(t) of the τ study's runs from its published lifetimes table (never its raw runs)
        tname = doc.get("tables", {}).get("lifetimes")
        if not tname:
            raise up.UpstreamError(f"{other}.json names no published lifetimes table ('tables': {{'lifetimes': …}})")
        life = up.table(study, other, tname)
        inputs["tau_lifetimes"] = {"source": f"{other}: derived/{tname}"}
        by_gamma = {float(g): d[["t_end", "outcome"]].reset_index(drop=True) for g, d in life.groupby("gamma")}
        if 0.0 not in by_gamma:
            raise up.UpstreamError(f"{other}'s {tname} has no γ = 0 rows (the conservative reference)")
        t0c, P0c, _ = _curve(by_gamma[0.0], dt)
        lifetimes = {g: by_gamma[g] for g in obs["gamma"] if g > 0 and g in by_gamma}
    except up.UpstreamError:
        if not up.dev_fallback_enabled():
            raise
        # development only: observed τ2 from this study's own E0 = 0.3 runs, no τ1 (no γ = 0 run)
        inputs["tau_table"] = {"source": up.DEV_SOURCE + ": own E0 runs, τ1 not available"}
        lifetimes = {g: read_lifetimes(study.raw(pair_key(e, g)), columns=["t_end", "outcome"])
                     for e, g in _pairs(study) if abs(e - E0) < 1e-12}
        obs = pd.DataFrame({"gamma": sorted(lifetimes), "tau1_observed": None, "tau1_err": None, "tau2_err": None,
                            "tau2_observed": [tau2_observed(lifetimes[g]) for g in sorted(lifetimes)]})
        t0c = P0c = None
    rows = []
    for r in obs[obs["gamma"] > 0].sort_values("gamma").itertuples():
        g = float(r.gamma)
        tau2_pred = tau2_predicted(E0, E_c, mu, g)
        row = {"gamma": g, "tau1_observed": _num(r.tau1_observed), "tau1_observed_err": _num(r.tau1_err),
               "tau2_observed": _num(r.tau2_observed), "tau2_observed_err": _num(r.tau2_err),
               "tau2_predicted": tau2_pred,
               "tau2_predicted_err": tau2_pred * mu_err / mu if math.isfinite(mu_err) else math.nan}
        lt = lifetimes.get(g)
        for h in hazards:
            row[f"tau1_pred_{h}"] = None
            row[f"f_ne_{h}"] = None
        if lt is not None:
            t, P, P_err = _curve(lt, dt)
            tf, Pf, sf = _fit_points(t, P, P_err, tau0, fit_dt, len(lt), min_count)
            if tf.size >= 5:
                fits = _homogeneous_fits(t, P, P_err, tf, Pf, sf, kappa=kappa, E0=E0, mu=mu, gamma=g, tau0=tau0,
                                         E_c=E_c, hazards=hazards, fit_tau2=False,
                                         P_min=min_count / len(lt) * 0.999)
                for h in hazards:
                    row[f"f_ne_{h}"] = float(fits[h].values["f_ne"])
                    row[f"rms_{h}"] = float(fits[h].rms_log_residual)
                    if t0c is not None:
                        row[f"tau1_pred_{h}"] = sm.predict_tau1(fits[h], (t0c, P0c), float(study.param("alpha")))
        rows.append(row)
    taus = pd.DataFrame(rows)
    gg = np.geomspace(min(taus["gamma"].min(), 1e-3) * 0.8, max(taus["gamma"].max(), 0.02) * 1.25, 200) \
        if len(taus) else np.geomspace(1e-3, 0.03, 200)
    t2 = tau2_predicted(E0, E_c, mu, gg)
    curve = pd.DataFrame({"gamma": gg, "tau2_predicted": t2,
                          "tau2_lo": t2 / (1 + mu_err / mu) if math.isfinite(mu_err) else t2,
                          "tau2_hi": t2 / (1 - mu_err / mu) if math.isfinite(mu_err) else t2})
    return taus, curve


def _val(v):
    """(value, err) of a numbers-JSON field: {"value", "err"} or a plain number (err None)."""
    if isinstance(v, dict):
        return _num(v.get("value")), _num(v.get("err"))
    return _num(v), None


def _num(v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def plot(study):
    """plot(study) -> None; Fig. 6 from the derived tables and fig6.json."""
    import pyarrow.parquet as pq

    from .figure import plot_fig6

    nums = study.read_numbers()
    read = lambda f: pq.read_table(study.out / "derived" / f).to_pandas()
    plot_fig6(read("curves.parquet"), read("fits.parquet"), read("tau_vs_gamma.parquet"),
              read("tau2_curve.parquet"), read("compare_fits.parquet"), nums, study.figure_path)
