"""Fig. 6 (paper fig:model_data_comparison): survival model vs simulations; τ1, τ2 vs γ; mixture model.

Draws what study fig6's analysis wrote; computes nothing.
"""
from __future__ import annotations

import numpy as np

from hhscatter.plotting import agg_pyplot

COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"]
LS = {"paper": (0, (5, 2)), "integrated": (0, (1.5, 1.5))}


def _pairs(curves):
    keys = curves[["pair", "E0", "gamma"]].drop_duplicates()
    return list(keys.sort_values(["E0", "gamma"]).itertuples(index=False))


def _curves_panel(ax, curves, models, tau0, title):
    """Simulated P(t) (steps) and model curves; ``models`` = [(column prefix, linestyle, legend label)]."""
    for i, (pair, E0, g) in enumerate(_pairs(curves)):
        c = curves[curves["pair"] == pair]
        col = COLORS[i % len(COLORS)]
        keep = c["P"] > 0
        ax.step(c["t"][keep], c["P"][keep], where="post", color=col, lw=1.6, alpha=0.75,
                label=f"$E_0={E0:g}$, $\\gamma={g:g}$")
        for name, ls, _ in models:
            if name not in c:
                continue
            m = c[name]
            ok = np.isfinite(m) & (m > 0)
            ax.plot(c["t"][ok], m[ok], color=col, lw=1.3, ls=ls)
    for _, ls, lab in models:
        ax.plot([], [], color="k", ls=ls, label=lab)
    ax.axvline(tau0, color="0.5", lw=0.8, ls=":")
    ax.text(tau0, 1.3, " $\\tau_0$", color="0.4", fontsize=8, va="bottom")
    ax.set_yscale("log")
    ax.set_xlabel("$t$")
    ax.set_ylabel("$P(t)$")
    ax.set_title(title, fontsize=10, loc="left")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="lower left", ncol=1)


def plot_fig6(curves, fits, taus, tau2_curve, cmps, nums, path):
    """plot_fig6(curves, fits, taus, tau2_curve, cmps, nums, path) -> None; writes the PNG.

    (a) simulated P(t) (steps) and the fitted homogeneous model, Eq.
    (eqn:surv_prob_model), with both hazard readings; (b) τ1 and τ2 vs γ at
    E0 = 0.3: observed (fig4, symbols) and predicted (τ2: Eq. (eq:tau2),
    dashed with the μ band; τ1: the fitted model against P_0, open symbols);
    (c) the mixture model on the same data; (d) RMS of the log residuals per
    pair and model.
    """
    plt = agg_pyplot()
    hazards = list(nums["config"]["study"].get("hazards", ["paper", "integrated"]))
    tau0 = float(nums["tau0"])
    fig, axs = plt.subplots(2, 2, figsize=(12, 10), constrained_layout=True)
    t_hi = float(np.nanmax(curves.loc[curves["P"] > 0, "t"]))
    _curves_panel(axs[0, 0], curves, [(f"homogeneous_{h}", LS.get(h, "--"), f"model, {h} hazard") for h in hazards],
                  tau0, "(a) simulations (steps) vs homogeneous model, Eq. (surv_prob_model)")
    h_mix = "integrated" if "integrated" in hazards else hazards[0]
    mixes = [v["name"] for v in nums["config"]["study"].get("mixtures", [])]
    shown = nums["config"]["study"].get("mixture_plotted") or (mixes[0] if mixes else None)
    _curves_panel(axs[1, 0], curves, [(f"homogeneous_{h_mix}", (0, (1.5, 1.5)), f"homogeneous, {h_mix} hazard"),
                                      (f"{shown}_{h_mix}", (0, (5, 2)), f"{shown.replace('_', ' ')}, {h_mix} hazard")],
                  tau0, f"(c) mixture ({shown.replace('_', ' ')}, K = {nums['config']['study'].get('n_components')}) "
                        "vs homogeneous model")
    ymin = max(float(np.nanmin(curves.loc[curves["P"] > 0, "P"])) * 0.5, 1e-7)
    for ax in (axs[0, 0], axs[1, 0]):
        ax.set_ylim(ymin, 3.0)
        ax.set_xlim(0, min(t_hi, 1.1 * float(np.nanmax(curves.loc[curves["P"] * curves["N"] >= 3, "t"]))))

    # (b) tau vs gamma
    ax = axs[0, 1]
    ax.fill_between(tau2_curve["gamma"], tau2_curve["tau2_lo"], tau2_curve["tau2_hi"], color=COLORS[1], alpha=0.15,
                    lw=0)
    ax.plot(tau2_curve["gamma"], tau2_curve["tau2_predicted"], color=COLORS[1], ls="--",
            label="$\\tau_2$ predicted, $\\ln(E_0/E_c)/(\\mu\\gamma)$")
    if len(taus):
        t2e = taus.get("tau2_observed_err")
        ax.errorbar(taus["gamma"], taus["tau2_observed"].astype(float),
                    yerr=None if t2e is None else t2e.astype(float), color=COLORS[1], marker="s", ls="none",
                    capsize=2, label="$\\tau_2$ observed (first settling, fig4)")
        t1e = taus.get("tau1_observed_err")
        ax.errorbar(taus["gamma"], taus["tau1_observed"].astype(float),
                    yerr=None if t1e is None else t1e.astype(float), color=COLORS[0], marker="o", ls="none",
                    capsize=2, label="$\\tau_1$ observed ($P_\\gamma = 2P_0$, fig4)")
        for h, mk in zip(hazards, ("D", "v", "^")):
            col = f"tau1_pred_{h}"
            if col in taus and np.isfinite(taus[col].astype(float)).any():
                ax.plot(taus["gamma"], taus[col].astype(float), color=COLORS[0], marker=mk, mfc="none",
                        ls=LS.get(h, "--"), lw=1.0, label=f"$\\tau_1$ model ({h} hazard)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("$\\gamma$")
    ax.set_ylabel("time")
    ax.set_title(f"(b) transition times at $E_0 = {nums['config']['study'].get('fig4_E0', 0.3):g}$, "
                 f"$\\mu = {nums['mu']['value']:.3f}$", fontsize=10, loc="left")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7)

    # (d) rms log residuals
    ax = axs[1, 1]
    pairs = _pairs(curves)
    models = [("homogeneous", h) for h in hazards] + [(m, h_mix) for m in mixes]
    w = 0.8 / len(models)
    x = np.arange(len(pairs))
    for j, (m, h) in enumerate(models):
        vals = []
        for p in pairs:
            r = fits[(fits["pair"] == p.pair) & (fits["model"] == m) & (fits["hazard"] == h)]
            vals.append(float(r["rms_log_residual"].iloc[0]) if len(r) else np.nan)
        ax.bar(x + (j - (len(models) - 1) / 2) * w, vals, width=w, color=COLORS[j % len(COLORS)],
               alpha=0.85 if m == "homogeneous" else 0.6, hatch="" if m == "homogeneous" else "//",
               label=f"{m.replace('_', ' ')}, {h} hazard")
    ax.set_xticks(x)
    ax.set_xticklabels([f"$E_0={p.E0:g}$\n$\\gamma={p.gamma:g}$" for p in pairs], fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("RMS of $\\ln P_{\\rm model} - \\ln P$ over the fitted points")
    ax.set_title("(d) goodness of fit on the same points (lower is better)", fontsize=10, loc="left")
    ax.grid(True, axis="y", which="both", alpha=0.25)
    vals_all = fits["rms_log_residual"].to_numpy(dtype=float)
    vals_all = vals_all[np.isfinite(vals_all) & (vals_all > 0)]
    if vals_all.size:
        ax.set_ylim(vals_all.min() / 2, vals_all.max() * 8)  # room for the legend above the bars
    ax.legend(fontsize=7, ncol=2, loc="upper center")
    if nums.get("dev_fallback"):
        fig.suptitle("DEVELOPMENT FALLBACK INPUTS — not a result", color="red")
    fig.savefig(path, dpi=150)
    plt.close(fig)
