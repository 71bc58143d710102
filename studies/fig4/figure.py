"""Fig 4 (paper fig:survprob): P(t) for several γ at E0 = 0.3 with τ0, τ1, τ2 marked for one γ,
and the ratio P_γ/P_0 that defines τ1.  Plot functions draw what they are given and compute nothing."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels
from hhscatter.publish.formatting import format_value_err

FIXED_COLORS = {0.0: "#1f77b4", 0.001: "#2ca02c", 0.002: "#bcbd22", 0.005: "#ff7f0e", 0.01: "#7b3294", 0.02: "#d62728"}


def _colors(gammas):
    """γ = 0 blue and γ = 0.01 purple as in the paper; other γ fixed colours, or a colour map for unlisted ones."""
    import matplotlib

    cmap = matplotlib.colormaps["viridis"]
    other = [g for g in gammas if g not in FIXED_COLORS]
    out = {g: FIXED_COLORS[g] for g in gammas if g in FIXED_COLORS}
    for k, g in enumerate(other):
        out[g] = cmap(0.1 + 0.8 * k / max(1, len(other) - 1))
    return out


def _pm(v, e):
    """'v \\pm e' for a LaTeX label: hhscatter.publish.formatting.format_value_err (the report's and the docs' rounding)."""
    return format_value_err(v, e, sep=r" \pm ")


def plot_fig4(surv, ratio, taus, numbers, path, *, mark_gamma=0.01):
    """plot_fig4(surv, ratio, taus, numbers, path, mark_gamma=0.01) -> None; writes Fig. 4.

    ``surv``: table fig4_survival (gamma, t, P, P_err); ``ratio``: fig4_ratio
    (gamma, t, ratio, n0); ``taus``: fig4_tau (one row per γ); ``numbers``:
    fig4.json.  (a) P(t) on log–log axes with ±1σ bands; for γ = mark_gamma
    the times τ0, τ1, τ2 (observed: first settling; predicted: Eq. (eq:tau2))
    are marked.  (b) P_γ/P_0 with the threshold α; dots at τ1 (open dots
    where N·P_0(τ1) is below the resolution threshold).
    """
    plt = agg_pyplot()
    gammas = sorted(surv["gamma"].unique())
    col = _colors(gammas)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11.5, 4.6), width_ratios=[1.35, 1], constrained_layout=True)

    for g in gammas:
        c = surv[(surv["gamma"] == g) & (surv["P"] > 0)]
        lab = r"$\gamma=0$ (conservative)" if g == 0 else rf"$\gamma={g:g}$"
        ax.plot(c["t"], c["P"], color=col[g], lw=1.8 if g in (0.0, mark_gamma) else 1.3, label=lab, zorder=3)
        lo = (c["P"] - c["P_err"]).clip(lower=c["P"] * 0.05)
        ax.fill_between(c["t"], lo, c["P"] + c["P_err"], color=col[g], alpha=0.2, lw=0)

    r = taus[taus["gamma"] == mark_gamma]
    if len(r):
        r = r.iloc[0]
        c = surv[(surv["gamma"] == mark_gamma) & (surv["P"] > 0)]
        marks = [
            (r["tau0"], r["tau0_err"], r"\tau_0", "o", "k", (6, -14)),
            (r["tau1"], r["tau1_err"], r"\tau_1", "s", "k", (6, 6)),
            (r["tau2_obs"], r["tau2_obs_err"], r"\tau_2^{\rm obs}", "v", "k", (-34, -16)),
            (r["tau2_pred"], r["tau2_pred_err"], r"\tau_2^{\rm pred}", "D", "#d62728", (6, 6)),
        ]
        lines = []
        for tv, te, lab, m, mc, off in marks:
            if not np.isfinite(tv):
                continue
            pv = np.interp(tv, c["t"], c["P"])
            ax.axvline(tv, color=mc, lw=0.7, ls=":", zorder=1)
            ax.plot(tv, pv, m, ms=7, mfc=col[mark_gamma] if mc == "k" else mc, mec="k", zorder=6)
            ax.annotate(f"${lab}$", (tv, pv), xytext=off, textcoords="offset points", fontsize=9, color=mc, zorder=7)
            lines.append(f"${lab} = {_pm(tv, te)}$")
        ax.text(
            0.985,
            0.985,
            rf"$\gamma={mark_gamma:g}$:" + "\n" + "\n".join(lines),
            transform=ax.transAxes,
            ha="right",
            va="top",
            fontsize=8.5,
            bbox={"boxstyle": "round,pad=0.3", "fc": "white", "ec": col[mark_gamma], "alpha": 0.9},
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    n = numbers["n_orbits_per_curve"]
    ax.set_ylim(0.3 / n, 1.5)
    ax.set_xlim(0.5, surv.loc[surv["P"] > 0, "t"].max() * 1.3)
    ax.set_xlabel(r"$t$")
    ax.set_ylabel(r"$P(t)$")
    ax.set_title(rf"$E_0={numbers['E0']:g}$, $N={n:,}$ per curve (same initial conditions)", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")
    ax.grid(True, which="major", alpha=0.3)

    for g in gammas[1:]:
        d = ratio[ratio["gamma"] == g]
        ok = d["n0"] >= 10
        bx.plot(d["t"][ok], d["ratio"][ok], color=col[g], lw=1.3, label=rf"$\gamma={g:g}$")
        bx.plot(d["t"][~ok], d["ratio"][~ok], color=col[g], lw=0.8, ls=":", alpha=0.7)
        rr = taus[taus["gamma"] == g].iloc[0]
        if np.isfinite(rr["tau1"]):
            filled = bool(rr["tau1_resolved"])
            bx.errorbar(
                rr["tau1"],
                numbers["alpha"],
                xerr=rr["tau1_err"] if np.isfinite(rr["tau1_err"]) else None,
                fmt="o",
                ms=6,
                color=col[g],
                mfc=col[g] if filled else "white",
                mec="k",
                capsize=2,
                zorder=5,
            )
    bx.axhline(numbers["alpha"], color="k", lw=0.9, ls="--", label=rf"$\alpha={numbers['alpha']:g}$")
    bx.set_yscale("log")
    bx.set_xlabel(r"$t$")
    bx.set_ylabel(r"$P_\gamma(t)/P_0(t)$")
    bx.set_ylim(0.5, 50)
    bx.set_xlim(0, min(150.0, float(ratio["t"].max())))
    bx.set_title(r"$\tau_1$: first $t\geq\tau_0$ with $P_\gamma=\alpha P_0$ (dots; dotted: $NP_0<10$)", fontsize=9)
    bx.legend(fontsize=8, loc="upper left")
    bx.grid(True, which="both", alpha=0.3)
    ax.text(0.01, 0.99, "(a)", transform=ax.transAxes, va="top", fontsize=10, fontweight="bold")
    bx.text(0.97, 0.03, "(b)", transform=bx.transAxes, ha="right", fontsize=10, fontweight="bold")
    fig.savefig(path, dpi=200)
    save_panels(fig, path, dpi=200)  # each panel legible at a page's full width
    plt.close(fig)
