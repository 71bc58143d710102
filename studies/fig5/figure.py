"""Fig. 5 (paper fig:um_comparison): dissipative section points vs the conservative c-measure, and distances.

Draws what study fig5's analysis wrote; computes nothing.
"""
from __future__ import annotations

import numpy as np

from hhscatter.publish.formatting import format_value_err
from hhscatter.publish.figures import agg_pyplot

RED = "#c0392b"
COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#17becf"]


def _scatter(ax, cm, pts, title, E1, E2, n_total):
    ax.scatter(cm["x"], cm["y"], s=0.6, c="k", lw=0, alpha=0.9, rasterized=True,
               label=f"$\\mu_c^{{E={E1:g}}}$ (conservative, {len(cm)} pts)")
    ax.scatter(pts["x"], pts["y"], s=0.6, c=RED, lw=0, alpha=0.55, rasterized=True,
               label=f"dissipative $E_0={E2:g}$ ({len(pts)} pts)")
    ax.set_aspect("equal")
    ax.set_xlim(-1.0, 1.0)
    ax.set_ylim(-1.0, 1.05)
    ax.set_xlabel("$x$")
    ax.set_ylabel("$y$")
    ax.set_title(title, fontsize=10, loc="left")
    leg = ax.legend(loc="lower left", fontsize=7, markerscale=12, frameon=True)
    leg.get_frame().set_alpha(0.85)


def _debiased(ax, tab, label, color, marker, ls="-", noise_max=0.5):
    """Debiased Hellinger vs box side with its 1σ band; uninformative box sizes hollow and dotted."""
    tab = tab.sort_values("box")
    ok = (tab["hellinger_noise"] <= noise_max).to_numpy()
    x = tab["box"].to_numpy()
    d = tab["hellinger_debiased"].to_numpy()
    lo, hi = tab["hellinger_debiased_lo"].to_numpy(), tab["hellinger_debiased_hi"].to_numpy()
    ax.errorbar(x[ok], d[ok], yerr=[d[ok] - lo[ok], hi[ok] - d[ok]], color=color, marker=marker, ms=4, lw=1.3,
                ls=ls, capsize=2, label=label)
    if (~ok).any():
        j = np.flatnonzero(~ok)
        j = np.append(j, j.max() + 1) if j.max() + 1 < len(x) else j  # join to the informative part
        ax.plot(x[j], d[j], color=color, marker=marker, ms=3, lw=0.8, ls=":", mfc="none", alpha=0.6)


def _box_axis(ax, boxes):
    ax.set_xscale("log")
    ax.set_xticks(boxes)
    ax.set_xticks([], minor=True)
    ax.set_xticklabels([f"{b:.3g}" for b in boxes], rotation=45, fontsize=8)
    ax.set_xlabel("box side $\\varepsilon$ (units of $x, y$)")


def plot_fig5(points, cmeasure, dist_tab, summary, nums, path):
    """plot_fig5(points, cmeasure, dist_tab, summary, nums, path) -> None; writes the PNG.

    ``points``: derived/points.parquet (gamma, set, x, y, energy); ``cmeasure``:
    derived/cmeasure_points.parquet (E, x, y); ``dist_tab``: distance_vs_scale
    rows (gamma, set, ref, box, hellinger_pq, hellinger_noise, *_std);
    ``summary``: distance_summary (sw1, agreement_scale); ``nums``: fig5.json.
    Panels (a), (b) as in the paper; (c) Hellinger excess over the split-half
    noise floor vs box side at the paper's γ; (d) the same for Fig. 5a against
    μ_c^{E1} at every γ with the agreement scales ε*.
    """
    plt = agg_pyplot()
    E1, E2, g0 = float(nums["E1"]), float(nums["E2"]), float(nums["gamma_main"])
    band = nums["band"]
    per_gamma = {float(r["gamma"]): r for r in nums["per_gamma"]}
    fig, axs = plt.subplots(2, 2, figsize=(11, 10.4), constrained_layout=True)
    cm1 = cmeasure[np.isclose(cmeasure["E"], E1)]
    ts = per_gamma[g0]["t_star"]
    pa = points[(points["gamma"] == g0) & (points["set"] == "a")]
    pb = points[(points["gamma"] == g0) & (points["set"] == "b")]
    _scatter(axs[0, 0], cm1, pa, f"(a) all orbits alive at $t^*={ts:.2f}$: first crossing $t\\geq t^*$ "
             f"($\\gamma={g0:g}$)", E1, E2, None)
    _scatter(axs[0, 1], cm1, pb, f"(b) as (a), crossing energy in [{band[0]:g}, {band[1]:g}]", E1, E2, None)

    noise_max = float(nums["config"]["study"].get("noise_max", 0.5))
    delta = float(nums.get("delta", 0.1))
    boxes = sorted(dist_tab["box"].unique())
    _distance_panel(axs[1, 0], dist_tab, summary, E1, E2, g0, boxes, noise_max, delta)
    _agreement_panel(axs[1, 1], dist_tab, summary, nums, per_gamma, E1, boxes, noise_max, delta)
    if nums.get("dev_fallback"):
        fig.suptitle("DEVELOPMENT FALLBACK INPUTS — not a result", color="red")
    fig.savefig(path, dpi=160)
    plt.close(fig)


def _distance_panel(ax, dist_tab, summary, E1, E2, g0, boxes, noise_max, delta):
    """Panel (c): debiased Hellinger distance to the c-measures vs box side at the paper's γ."""
    styles = [("a", "E1", COLORS[0], "o", "-"), ("a", "E2", COLORS[0], "s", "--"),
              ("b", "E1", COLORS[1], "o", "-"), ("b", "E2", COLORS[1], "s", "--")]
    for s, ref, col, mk, ls in styles:
        tab = dist_tab[(dist_tab["gamma"] == g0) & (dist_tab["set"] == s) & (dist_tab["ref"] == ref)]
        if len(tab):
            row = summary[(summary["gamma"] == g0) & (summary["set"] == s) & (summary["ref"] == ref)].iloc[0]
            Eref = E1 if ref == "E1" else E2
            _debiased(ax, tab, f"Fig. 5{s} vs $\\mu_c^{{{Eref:g}}}$ (m={int(tab['m'].iloc[0])}; "
                      f"SW$_1$={format_value_err(row['sw1'], row['sw1_err'], sep='±')}, floor {row['sw1_noise_m']:.3f})",
                      col, mk, ls, noise_max)
    ref_tab = dist_tab[dist_tab["set"] == "cm_E2"]
    if len(ref_tab):
        row = summary[summary["set"] == "cm_E2"].iloc[0]
        _debiased(ax, ref_tab, f"$\\mu_c^{{{E2:g}}}$ vs $\\mu_c^{{{E1:g}}}$ (m={int(ref_tab['m'].iloc[0])}; "
                  f"SW$_1$={format_value_err(row['sw1'], row['sw1_err'], sep='±')})", "0.45", "^", "-.", noise_max)
    ax.axhline(delta, color="k", lw=0.8, ls=":")
    _box_axis(ax, boxes)
    ax.set_ylim(0, 1.3 * ax.get_ylim()[1])  # room for the legend
    ax.set_ylabel("debiased Hellinger $\\sqrt{H_{PQ}^2 - H_{\\rm noise}^2}$")
    ax.set_title(f"(c) distance to the c-measures vs scale, $\\gamma={g0:g}$ (1σ bands)", fontsize=10, loc="left")
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(True, which="major", alpha=0.3)


def _agreement_panel(ax, dist_tab, summary, nums, per_gamma, E1, boxes, noise_max, delta):
    """Panel (d): Fig. 5a vs μ_c^{E1} at every γ with the agreement scales ε*."""
    gammas = sorted(per_gamma)
    for i, g in enumerate(gammas):
        tab = dist_tab[(dist_tab["gamma"] == g) & (dist_tab["set"] == "a") & (dist_tab["ref"] == "E1")]
        if not len(tab):
            continue
        row = summary[(summary["gamma"] == g) & (summary["set"] == "a") & (summary["ref"] == "E1")].iloc[0]
        eps, eps_z = row["agreement_scale_debiased"], row["agreement_scale"]
        col = COLORS[(i + 2) % len(COLORS)]
        fmt = lambda e: f"{e:.3g}" if e is not None and np.isfinite(e) else "none"
        lab = (f"$\\gamma={g:g}$, $t^*={per_gamma[g]['t_star']:.1f}$: $\\varepsilon^*_\\delta$={fmt(eps)}, "
               f"$\\varepsilon^*_{{2\\sigma}}$={fmt(eps_z)}")
        if not bool(row["common_m"]):
            lab += " (own m)"
        _debiased(ax, tab, lab, col, "o", "-", noise_max)
        if eps is not None and np.isfinite(eps):
            ax.axvline(eps, color=col, ls=":", lw=1.2)
    ax.axhline(delta, color="k", lw=0.8, ls=":")
    ax.text(max(boxes), delta, f" $\\delta$ = {delta:g}", va="bottom", ha="right", fontsize=8)
    _box_axis(ax, boxes)
    ax.set_ylim(bottom=0)
    ax.set_ylabel(f"debiased Hellinger, Fig. 5a vs $\\mu_c^{{{E1:g}}}$")
    ax.set_title(f"(d) convergence with relaxation time $t^*$ (common m = {nums['m_common']})",
                 fontsize=10, loc="left")
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(True, which="major", alpha=0.3)
