"""Fig. 6 (paper fig:model_data_comparison): survival model vs simulations; τ1, τ2 vs γ; mixture model.

Draws what study fig6's analysis wrote; computes nothing.
"""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels

COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"]
LS = {"paper": (0, (5, 2)), "integrated": (0, (1.5, 1.5))}
# the same model with the paper's constants: dash-dotted, thinner, so that each reads as the twin of our curve
LS_PC = {"paper": (0, (7, 1.5, 1.5, 1.5)), "integrated": (0, (3, 1.2, 1, 1.2, 1, 1.2))}
PC = "paper_constants"  # study fig6's name of the model with the paper's constants (columns, tables)


def _pairs(curves):
    keys = curves[["pair", "E0", "gamma"]].drop_duplicates()
    return list(keys.sort_values(["E0", "gamma"]).itertuples(index=False))


def _curves_panel(ax, curves, models, tau0, title, ncol=1):
    """Simulated P(t) (steps) and model curves; ``models`` = [(column, linestyle, legend label[, line width])]."""
    for i, (pair, E0, g) in enumerate(_pairs(curves)):
        c = curves[curves["pair"] == pair]
        col = COLORS[i % len(COLORS)]
        keep = c["P"] > 0
        ax.step(
            c["t"][keep],
            c["P"][keep],
            where="post",
            color=col,
            lw=1.6,
            alpha=0.75,
            label=f"$E_0={E0:g}$, $\\gamma={g:g}$",
        )
        for name, ls, _, *lw in models:
            if name not in c:
                continue
            m = c[name]
            ok = np.isfinite(m) & (m > 0)
            ax.plot(c["t"][ok], m[ok], color=col, lw=lw[0] if lw else 1.3, ls=ls)
    for _, ls, lab, *lw in models:
        ax.plot([], [], color="k", ls=ls, lw=lw[0] if lw else 1.3, label=lab)
    ax.axvline(tau0, color="0.5", lw=0.8, ls=":")
    ax.text(tau0, 1.3, " $\\tau_0$", color="0.4", fontsize=8, va="bottom")
    ax.set_yscale("log")
    ax.set_xlabel("$t$")
    ax.set_ylabel("$P(t)$")
    ax.set_title(title, fontsize=10, loc="left")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="lower left", ncol=ncol)


def plot_fig6(curves, fits, taus, tau2_curve, cmps, nums, path, pc_fits=None, pc_taus=None):
    """plot_fig6(curves, fits, taus, tau2_curve, cmps, nums, path, pc_fits=None, pc_taus=None) -> None; writes the PNG.

    (a) simulated P(t) (steps) and the fitted homogeneous model, Eq.
    (eqn:surv_prob_model), with both hazard readings, with our constants
    (κ0(E) of fig2, μ of fig3) and, thinner and dash-dotted, with the
    paper's (``pc_fits``; curves ``paper_constants_<hazard>``); (b) τ1 and τ2
    vs γ at E0 = 0.3: observed (fig4, symbols) and predicted (τ2: Eq.
    (eq:tau2), dashed with the μ band, dash-dotted with the paper's μ; τ1:
    the fitted model against P_0, open symbols, crosses with the paper's
    constants, ``pc_taus``); (c) the mixture model on the same data; (d) RMS
    of the log residuals per pair and model, both sets of constants.
    """
    plt = agg_pyplot()
    hazards = list(nums["config"]["study"].get("hazards", ["paper", "integrated"]))
    tau0 = float(nums["tau0"])
    fig, axs = plt.subplots(2, 2, figsize=(12, 10), constrained_layout=True)
    t_hi = float(np.nanmax(curves.loc[curves["P"] > 0, "t"]))
    pc = nums.get(PC, {}).get("constants")
    models_a = [
        (f"homogeneous_{h}", LS.get(h, "--"), f"model, {h} hazard,\nour $\\kappa_0(E)$, $\\mu$ (fig2, fig3)")
        for h in hazards
    ]
    models_a += [
        (f"{PC}_{h}", LS_PC.get(h, "-."), f"model, {h} hazard,\npaper's $\\kappa_0(E)$, $\\mu$", 0.9) for h in hazards
    ]
    _curves_panel(axs[0, 0], curves, models_a, tau0, "(a) simulations (steps) vs homogeneous model, Eq. (18)", ncol=2)
    h_mix = "integrated" if "integrated" in hazards else hazards[0]
    mixes = [v["name"] for v in nums["config"]["study"].get("mixtures", [])]
    shown = nums["config"]["study"].get("mixture_plotted") or (mixes[0] if mixes else None)
    _curves_panel(
        axs[1, 0],
        curves,
        [
            (f"homogeneous_{h_mix}", (0, (1.5, 1.5)), f"homogeneous, {h_mix} hazard"),
            (f"{shown}_{h_mix}", (0, (5, 2)), f"{shown.replace('_', ' ')}, {h_mix} hazard"),
        ],
        tau0,
        f"(c) mixture ({shown.replace('_', ' ')}, K = {nums['config']['study'].get('n_components')}) "
        "vs homogeneous model",
    )
    ymin = max(float(np.nanmin(curves.loc[curves["P"] > 0, "P"])) * 0.5, 1e-7)
    for ax in (axs[0, 0], axs[1, 0]):
        ax.set_ylim(ymin, 3.0)
        ax.set_xlim(0, min(t_hi, 1.1 * float(np.nanmax(curves.loc[curves["P"] * curves["N"] >= 3, "t"]))))

    _tau_panel(axs[0, 1], taus, tau2_curve, nums, hazards, pc, pc_taus)
    _residuals_panel(axs[1, 1], curves, fits, pc_fits, hazards, mixes, h_mix)
    if nums.get("dev_fallback"):
        fig.suptitle("DEVELOPMENT FALLBACK INPUTS — not a result", color="red")
    fig.savefig(path, dpi=150)
    save_panels(fig, path, dpi=150)  # each panel legible at a page's full width
    plt.close(fig)


def _tau_panel(ax, taus, tau2_curve, nums, hazards, pc, pc_taus):
    """Panel (b): τ1 and τ2 vs γ, observed (fig4) and predicted with our constants and the paper's."""
    ax.fill_between(
        tau2_curve["gamma"], tau2_curve["tau2_lo"], tau2_curve["tau2_hi"], color=COLORS[1], alpha=0.15, lw=0
    )
    ax.plot(
        tau2_curve["gamma"],
        tau2_curve["tau2_predicted"],
        color=COLORS[1],
        ls="--",
        label="$\\tau_2$ predicted, $\\ln(E_0/E_c)/(\\mu\\gamma)$, our $\\mu$",
    )
    if f"tau2_predicted_{PC}" in tau2_curve and pc is not None:
        ax.plot(
            tau2_curve["gamma"],
            tau2_curve[f"tau2_predicted_{PC}"],
            color=COLORS[1],
            ls=LS_PC["paper"],
            lw=0.9,
            label=f"$\\tau_2$ predicted, paper's $\\mu = {pc['mu']:g}$",
        )
    if len(taus):
        t2e = taus.get("tau2_observed_err")
        ax.errorbar(
            taus["gamma"],
            taus["tau2_observed"].astype(float),
            yerr=None if t2e is None else t2e.astype(float),
            color=COLORS[1],
            marker="s",
            ls="none",
            capsize=2,
            label="$\\tau_2$ observed (first settling, fig4)",
        )
        t1e = taus.get("tau1_observed_err")
        ax.errorbar(
            taus["gamma"],
            taus["tau1_observed"].astype(float),
            yerr=None if t1e is None else t1e.astype(float),
            color=COLORS[0],
            marker="o",
            ls="none",
            capsize=2,
            label="$\\tau_1$ observed ($P_\\gamma = 2P_0$, fig4)",
        )
        for h, mk in zip(hazards, ("D", "v", "^")):
            col = f"tau1_pred_{h}"
            if col in taus and np.isfinite(taus[col].astype(float)).any():
                ax.plot(
                    taus["gamma"],
                    taus[col].astype(float),
                    color=COLORS[0],
                    marker=mk,
                    mfc="none",
                    ls=LS.get(h, "--"),
                    lw=1.0,
                    label=f"$\\tau_1$ model ({h} hazard), our constants",
                )
    if pc_taus is not None and len(pc_taus):
        for h, mk in zip(hazards, ("x", "+", "1")):
            col = f"tau1_pred_{h}"
            if col in pc_taus and np.isfinite(pc_taus[col].astype(float)).any():
                ax.plot(
                    pc_taus["gamma"],
                    pc_taus[col].astype(float),
                    color=COLORS[0],
                    marker=mk,
                    ms=7,
                    ls=LS_PC.get(h, "-."),
                    lw=0.9,
                    label=f"$\\tau_1$ model ({h} hazard), paper's constants",
                )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("$\\gamma$")
    ax.set_ylabel("time")
    ax.set_title(
        f"(b) transition times at $E_0 = {nums['config']['study'].get('fig4_E0', 0.3):g}$, "
        f"$\\mu = {nums['mu']['value']:.3f}$ (ours)" + (f", {pc['mu']:g} (paper's)" if pc is not None else ""),
        fontsize=10,
        loc="left",
    )
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7)


def _residuals_panel(ax, curves, fits, pc_fits, hazards, mixes, h_mix):
    """Panel (d): RMS log residual per pair and model on the same points, both sets of constants."""
    pairs = _pairs(curves)
    models = [("homogeneous", h) for h in hazards]
    if pc_fits is not None and len(pc_fits):
        models += [(PC, h) for h in hazards]
    models += [(m, h_mix) for m in mixes]
    w = 0.8 / len(models)
    x = np.arange(len(pairs))
    hatch = {"homogeneous": "", PC: ".."}
    for j, (m, h) in enumerate(models):
        vals = []
        for p in pairs:
            tab = pc_fits if m == PC else fits[fits["model"] == m]
            r = tab[(tab["pair"] == p.pair) & (tab["hazard"] == h)]
            vals.append(float(r["rms_log_residual"].iloc[0]) if len(r) else np.nan)
        lab = (
            f"homogeneous, {h} hazard, paper's constants"
            if m == PC
            else f"{m.replace('_', ' ')}, {h} hazard" + (", our constants" if m == "homogeneous" else "")
        )
        # the two constants' bars of one hazard share its colour (the dotted one is the paper's constants);
        # the mixtures keep the colours after the hazards'
        k = hazards.index(h) if m in hatch else len(hazards) + mixes.index(m)
        ax.bar(
            x + (j - (len(models) - 1) / 2) * w,
            vals,
            width=w,
            color=COLORS[k % len(COLORS)],
            alpha=0.85 if m == "homogeneous" else 0.6,
            hatch=hatch.get(m, "//"),
            label=lab,
        )
    ax.set_xticks(x)
    ax.set_xticklabels([f"$E_0={p.E0:g}$\n$\\gamma={p.gamma:g}$" for p in pairs], fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("RMS of $\\ln P_{\\rm model} - \\ln P$ over the fitted points")
    ax.set_title("(d) goodness of fit on the same points (lower is better)", fontsize=10, loc="left")
    ax.grid(True, axis="y", which="both", alpha=0.25)
    vals_all = np.concatenate(
        [fits["rms_log_residual"].to_numpy(dtype=float)]
        + ([pc_fits["rms_log_residual"].to_numpy(dtype=float)] if pc_fits is not None else [])
    )
    vals_all = vals_all[np.isfinite(vals_all) & (vals_all > 0)]
    if vals_all.size:
        ax.set_ylim(vals_all.min() / 2, vals_all.max() * 8)  # room for the legend above the bars
    ax.legend(fontsize=7, ncol=2, loc="upper center")
