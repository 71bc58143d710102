"""Claims 4, 6 and 7: τ0, τ1, τ2 against γ; the survival model; κγ(t) against κ0(E(t))."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.transitions import (
    bootstrap_transition_times,
    power_law_exponent,
    settle_time_quantiles,
    survival_on_grid,
    tau1,
    tau2_observed_interval,
    tau2_predicted,
)
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import signed
from hhscatter.analysis.survival.effective_rate import (
    binned_hazard,
    observed_over_expected,
)
from hhscatter.analysis.survival.fits import (
    observed_from_outcome,
    survival_from_lifetimes,
)
from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
from hhscatter.analysis.survival.windows import choose_windows
from hhscatter.reproduction.claims.keys import diss_key
from hhscatter.reproduction.claims.records import z_verdict
from hhscatter.reproduction.hazard_fits import fit_homogeneous_hazards, survival_fit_points


def taus(runs, label, m, E0, mu, mu_err):
    """τ0 (P_0), τ1 (P_γ = α P_0), τ2 observed (first settling) and Eq. (eq:tau2) per γ; paired bootstrap."""
    p = runs.params
    gs = list(p.gammas)
    lts = {g: runs.lifetimes(diss_key(label, g)).sort_values("traj_id", ignore_index=True) for g in gs}
    N = len(lts[0.0])
    t_last = max(float(lt["t_end"].max()) for lt in lts.values())
    grid = np.round(np.arange(0.0, t_last + p.tau_grid_step, p.tau_grid_step), 9)
    P = {
        g: survival_on_grid(lt["t_end"].to_numpy(), observed_from_outcome(lt["outcome"]), grid) for g, lt in lts.items()
    }

    def rule(t, P0, n):
        return choose_windows(t, P0, n_total=n).tau0

    tau0 = float(rule(grid, P[0.0], N))
    boot = bootstrap_transition_times(
        {g: (lt["t_end"].to_numpy(), lt["outcome"].to_numpy()) for g, lt in lts.items()},
        0.0,
        grid,
        tau0=rule,
        alpha=p.alpha,
        n_boot=p.n_boot,
        seed=p.fit_seed,
    )
    rows = []
    for g in gs[1:]:
        b = boot[boot["label"] == g]

        def sd(col, b=b):
            v = b[col].to_numpy(float)
            v = v[np.isfinite(v)]
            return float(np.std(v, ddof=1)) if v.size > 1 else math.nan

        t1 = tau1(grid, P[g], P[0.0], tau0, p.alpha)
        t2 = tau2_observed_interval(lts[g])
        q = settle_time_quantiles(lts[g]["t_end"].to_numpy(), lts[g]["outcome"], (0.01, 0.5))
        pred = float(tau2_predicted(E0, m.critical_energy, mu, g))
        rows.append(
            {
                "system": label,
                "gamma": g,
                "n": N,
                "tau0": tau0,
                "tau0_err": float(boot["tau0"].std(ddof=1)),
                "tau1": math.nan if t1 is None else t1,
                "tau1_err": sd("tau1"),
                "tau2_obs": math.nan if t2.n_settled == 0 else t2.value,
                "tau2_obs_lo": math.nan if t2.n_settled == 0 else t2.lo,
                "tau2_obs_hi": math.nan if t2.n_settled == 0 else t2.hi,
                "f_settled": float(np.mean(lts[g]["outcome"] == "settled")),
                "p0_trapped": float(np.mean(lts[0.0]["outcome"] == "censored")),
                "t_settle_q50": math.nan if q is None else float(q[1]),
                "t_settle_q50_err": sd("t_settle_q0.5"),
                "tau2_pred": pred,
                "tau2_pred_err": pred * mu_err / mu,
            }
        )
    return pd.DataFrame(rows)


def claim4(claims, label, taus: pd.DataFrame, mu_gamma):
    claims.add(
        "4",
        "τ0 (on P_0)",
        label,
        float(taus["tau0"].iloc[0]),
        float(taus["tau0_err"].iloc[0]),
        "measured",
        "choose_windows on the conservative curve",
    )
    t1 = taus["tau1"].to_numpy()
    ok = np.isfinite(t1)
    mono = bool(np.all(np.diff(t1[ok]) <= 0)) if ok.sum() > 1 else None
    p1, p1e = power_law_exponent(taus["gamma"], taus["tau1"], taus["tau1_err"])
    undefined = ", ".join(f"{g:g}" for g, v in zip(taus["gamma"], t1) if not np.isfinite(v))
    claims.add(
        "4",
        "τ1 ∝ γ^−p1",
        label,
        p1,
        p1e,
        (
            f"undetermined: P_γ never reaches α P_0 after τ0 = {taus['tau0'].iloc[0]:.0f} at γ = {undefined} "
            f"(τ2 by Eq. (eq:tau2) = {', '.join(f'{v:.0f}' for v in taus['tau2_pred'])}: the irregular regime "
            f"outlasts the dissipative one; P_0 keeps {taus['p0_trapped'].iloc[0]:.0%} orbits to t_max)"
        )
        if mono is None
        else ("τ1 increases as γ decreases" if mono else "τ1 not monotone in γ")
        + (f"; undefined at γ = {undefined}" if undefined and mono is not None else ""),
        "paper: τ1 and τ2 increase with decreasing γ; a linear κ0(E) gives p1 = 1/2",
    )
    p50, p50e = power_law_exponent(taus["gamma"], taus["t_settle_q50"], taus["t_settle_q50_err"])
    claims.add(
        "4",
        "median settling time ∝ γ^−p",
        label,
        p50,
        p50e,
        z_verdict(p50, p50e, 1.0, "τ2 ∝ 1/γ", "not ∝ 1/γ"),
        "Eq. (eq:tau2): p = 1 (N-independent)",
        1.0,
    )
    r = taus[taus["gamma"] == mu_gamma]
    if len(r) and np.isfinite(r["tau2_obs"].iloc[0]):
        r = r.iloc[0]
        ratio, ratio_err = tau2_ratio(
            r["tau2_obs"], r["tau2_obs_lo"], r["tau2_obs_hi"], r["tau2_pred"], r["tau2_pred_err"]
        )
        claims.add(
            "4",
            f"τ2 observed / Eq. (eq:tau2) at γ = {mu_gamma:g}",
            label,
            ratio,
            ratio_err,
            z_verdict(ratio, ratio_err, 1.0, "agrees", "differs"),
            f"τ2,obs = {r['tau2_obs']:.1f} (first settling, N = {int(r['n'])}: decreases with N; its error is the "
            f"half-width of the order-statistic interval [{r['tau2_obs_lo']:.1f}, {r['tau2_obs_hi']:.1f}] of the "
            f"quantile t_1/N, as in fig4), ln(E0/E_c)/(μγ) = "
            f"{r['tau2_pred']:.{_decimals(r['tau2_pred_err'])}f} ± {r['tau2_pred_err']:.{_decimals(r['tau2_pred_err'])}f} "
            "with μ measured",
            1.0,
        )


def tau2_ratio(obs, lo, hi, pred, pred_err) -> tuple[float, float]:
    """tau2_ratio(τ2,obs, its interval lo, hi, τ2 by Eq. (eq:tau2), its 1σ) -> (ratio, 1σ): τ2,obs/τ2,pred with the
    half-width of the order-statistic interval as the observed value's error (fig4's convention) and both errors
    propagated; both NaN without a finite observed value or interval.

    Examples
    --------
    >>> r, e = tau2_ratio(58.0, 0.0, 58.0, 62.5, 0.01)   # interval [0, τ2,obs] at p = 1/N: half-width 29
    >>> round(r, 4), round(e, 4)
    (0.928, 0.464)
    """
    vals = [float(v) for v in (obs, lo, hi, pred, pred_err)]
    if not all(math.isfinite(v) for v in vals) or vals[0] <= 0 or vals[3] <= 0:
        return math.nan, math.nan
    obs, lo, hi, pred, pred_err = vals
    r = Measured(obs, 0.5 * (hi - lo)) / Measured(pred, pred_err)
    return r.value, r.err


def _decimals(err: float) -> int:
    """Decimal places that show an error to two significant digits (never "± 0.0" for a small error)."""
    return max(1, 1 - int(np.floor(np.log10(err)))) if np.isfinite(err) and err > 0 else 1


def fit_claim6(runs, label, m, per, taus, E0, mu) -> dict:
    """The survival model, Eq. (eqn:surv_prob_model), both hazards, fig6's fitting rule, at γ = mu_gamma, of one
    system: {conv, tau0, reason, fits {hazard: fit}, curve}; verdicts by :func:`claim6` once every system is fitted."""
    p = runs.params
    conv = "plateau" if per.get("plateau") else "escaping"
    law = per.get(conv)
    g = p.mu_gamma
    if law is None:
        return {
            "conv": conv,
            "tau0": None,
            "fits": {},
            "curve": None,
            "reason": "no κ0(E) law fitted (fewer than 5 defined points)",
            "law": False,
        }
    ec = m.critical_energy
    kappa = PiecewiseKappa(
        E_c=ec,
        a2=law["a"]["value"] / ec**2,
        a1=law["b"]["value"] / ec,
        slope=law["c"]["value"] / ec,
        E_switch=ec * (1 + law["eps_b"]["value"]),
    )
    lt = runs.lifetimes(diss_key(label, g))
    n = len(lt)
    c = survival_from_lifetimes(lt[["t_end", "outcome"]], np.arange(0.0, float(lt["t_end"].max()) + p.sm_dt, p.sm_dt))
    tau0 = float(taus["tau0"].iloc[0])
    tf, Pf, sf = survival_fit_points(c.t, c.P, c.P_err, tau0, p.sm_fit_dt, n, p.sm_min_count)
    reason = ""
    tau2 = float(taus.loc[taus["gamma"] == g, "tau2_pred"].iloc[0])
    try:
        if tau0 >= tau2:  # the model's escape regime [τ0, τ2] is empty
            raise ValueError(
                f"τ0 = {tau0:.0f} (on P_0) ≥ τ2 = {tau2:.0f} by Eq. (eq:tau2): the model has no escape regime"
            )
        with counted("claims.dissipative.fit_homogeneous_hazards"):
            fits = fit_homogeneous_hazards(
                c.t,
                c.P,
                c.P_err,
                tf,
                Pf,
                sf,
                kappa=kappa,
                E0=E0,
                mu=mu,
                gamma=g,
                tau0=tau0,
                E_c=ec,
                hazards=["paper", "integrated"],
                fit_tau2=False,
                P_min=p.sm_min_count / n * 0.999,
            )
    except (RuntimeError, ValueError) as exc:
        fits, reason = {}, str(exc)
    return {"conv": conv, "tau0": tau0, "fits": fits, "curve": c, "reason": reason, "law": True}


def claim6(claims, results: dict, reference: str | None, p) -> dict:
    """claim6(claims, {label: fit_claim6(...)}, reference, p) -> {label: {hazard: JSON record}}.

    Records per system in the order of ``results``; the verdict compares each system's RMS log residual with that
    of the ``reference`` label (Hénon–Heiles) wherever it stands in the order (None: no reference, verdicts
    undetermined).
    """
    g = p.mu_gamma
    ref = {h: f.rms_log_residual for h, f in results[reference]["fits"].items()} if reference in results else {}
    out = {}
    for label, res in results.items():
        out[label] = {}
        for h in ("paper", "integrated"):
            q = f"survival model ({h} hazard) at γ = {g:g}: rms log residual"
            f = res["fits"].get(h)
            if not res["law"]:
                claims.add("6", q, label, None, None, "undetermined", res["reason"])
                continue
            if f is None:
                claims.add("6", q, label, None, None, f"not applicable: {res['reason']}", "fig6's rule could not fit")
                continue
            r = ref.get(h)
            verdict = (
                "reference (Hénon–Heiles)"
                if label == reference
                else "undetermined: no Hénon–Heiles reference"
                if r is None
                else "as good as on Hénon–Heiles (rms ≤ 1.5× its)"
                if f.rms_log_residual <= 1.5 * r
                else f"worse than on Hénon–Heiles ({f.rms_log_residual / r:.1f}× its rms)"
            )
            tau0, c = res["tau0"], res["curve"]
            claims.add(
                "6",
                q,
                label,
                f.rms_log_residual,
                None,
                verdict,
                f"fig6's rule (points every {p.sm_fit_dt:g} from τ0 = {tau0:.1f} with N·P ≥ {p.sm_min_count:g}, "
                f"P(τ0) held, best of 3 starts); κ0(E) the {res['conv']} law, μ measured; χ²/dof = "
                f"{f.chi2_red:.3g} over {f.n_points} points (correlated Kaplan–Meier points: indicative)",
            )
            out[label][h] = {
                "rms_log_residual": f.rms_log_residual,
                "chi2_red": f.chi2_red,
                "n_points": f.n_points,
                "values": {k: float(v) for k, v in f.values.items() if np.ndim(v) == 0},
                "curve": {
                    "t": c.t[c.t >= tau0][::4].tolist(),
                    "P": c.P[c.t >= tau0][::4].tolist(),
                    "model": [float(x) for x in f.predict(c.t[c.t >= tau0][::4])],
                },
            }
    return out


def claim7(runs, claims, label, m, table, taus, E0, mu):
    """κγ(t) = κ0(E(t)) for the smallest γ: escapes observed over those expected from κ0 at E0 e^{−μγt}."""
    p = runs.params
    g = min(x for x in p.gammas if x > 0)
    conv = "plateau"
    k = table[(table["convention"] == conv) & table["defined"]].sort_values("eps")
    if len(k) < 2:
        conv = "escaping"
        k = table[(table["convention"] == conv) & table["defined"]].sort_values("eps")
    lt = runs.lifetimes(diss_key(label, g))
    t_end = lt["t_end"].to_numpy()
    esc = (lt["outcome"] == "escaped").to_numpy()
    tau0 = float(taus["tau0"].iloc[0])
    t_lo_e = math.log(E0 / (m.critical_energy * (1 + float(k["eps"].min())))) / (mu * g) if len(k) else tau0
    edges = np.arange(tau0, max(tau0, t_lo_e) + 1e-9, p.hazard_bin)
    if len(k) < 2 or edges.size < 2:
        why = (
            "κ0 defined at fewer than 2 energies"
            if len(k) < 2
            else f"τ0 = {tau0:.0f} comes after E(t) has reached the lowest defined κ0 energy (t = {t_lo_e:.0f})"
        )
        claims.add(
            "7",
            f"κγ(t)/κ0(E(t)) at γ = {g:g} (observed/expected escapes)",
            label,
            None,
            None,
            f"undetermined: {why}",
            f"{conv} κ0 points",
        )
        return None
    b = binned_hazard(t_end, esc, edges)
    at_risk = b["exposure"] / p.hazard_bin
    b = b[at_risk >= p.min_survivors]
    eps_t = E0 * np.exp(-mu * g * b["t_mid"].to_numpy()) / m.critical_energy - 1
    lk = np.interp(eps_t, k["eps"], np.log(k["kappa"]), left=np.nan, right=np.nan)
    b = b.assign(eps=eps_t, kappa0=np.exp(lk))
    r, e, expected = observed_over_expected(b, b["kappa0"])
    claims.add(
        "7",
        f"κγ(t)/κ0(E(t)) at γ = {g:g} (observed/expected escapes)",
        label,
        r,
        e,
        z_verdict(r, e, 1.0, "κγ(t) = κ0(E(t))", f"κγ differs from κ0(E(t)) by {signed(100 * (r - 1), '+.0f')} %"),
        f"bins of {p.hazard_bin:g} from τ0 = {tau0:.1f} while E(t) = E0 e^(−μγt) ≥ the lowest defined κ0 "
        f"energy; κ0 interpolated (log) between the {conv} points; {expected:.0f} escapes expected",
        1.0,
    )
    return b.assign(system=label, gamma=g, convention=conv)
