"""Fig. 5 (paper fig:um_comparison): dissipative section points vs the conservative c-measure, and distances.

Draws what study fig5's analysis wrote; computes nothing.
"""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels
from hhscatter.publish.formatting import format_value_err

RED = "#c0392b"
COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#17becf"]


def _scatter(ax, cm, pts, title, E1, E2, n_total):
    ax.scatter(
        cm["x"],
        cm["y"],
        s=0.6,
        c="k",
        lw=0,
        alpha=0.9,
        rasterized=True,
        label=f"$\\mu_c^{{E={E1:g}}}$ (conservative, {len(cm)} pts)",
    )
    ax.scatter(
        pts["x"],
        pts["y"],
        s=0.6,
        c=RED,
        lw=0,
        alpha=0.55,
        rasterized=True,
        label=f"dissipative $E_0={E2:g}$ ({len(pts)} pts)",
    )
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
    ax.errorbar(
        x[ok],
        d[ok],
        yerr=[d[ok] - lo[ok], hi[ok] - d[ok]],
        color=color,
        marker=marker,
        ms=4,
        lw=1.3,
        ls=ls,
        capsize=2,
        label=label,
    )
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
    Panels (a), (b) as in the paper; (c) debiased Hellinger distance vs box
    side at the paper's γ; (d) the same for Fig. 5a against μ_c^{E1} at every
    γ with the agreement scales ε*_δ; both with percentile bands over paired
    half-samples of orbits (fig5.json ``refs_paired``, ``panel_d``).
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
    _scatter(
        axs[0, 0],
        cm1,
        pa,
        f"(a) all orbits alive at $t^*={ts:.2f}$: first crossing $t\\geq t^*$ ($\\gamma={g0:g}$)",
        E1,
        E2,
        None,
    )
    _scatter(axs[0, 1], cm1, pb, f"(b) as (a), crossing energy in [{band[0]:g}, {band[1]:g}]", E1, E2, None)

    noise_max = float(nums["config"]["study"].get("noise_max", 0.5))
    delta = float(nums.get("delta", 0.1))
    boxes = sorted(dist_tab["box"].unique())
    _distance_panel(axs[1, 0], dist_tab, summary, E1, E2, g0, boxes, noise_max, delta, nums)
    _agreement_panel(axs[1, 1], dist_tab, summary, nums, per_gamma, E1, boxes, noise_max, delta)
    if nums.get("dev_fallback"):
        fig.suptitle("DEVELOPMENT FALLBACK INPUTS — not a result", color="red")
    fig.savefig(path, dpi=160)
    save_panels(fig, path, dpi=160)  # each panel legible at a page's full width
    plt.close(fig)


def _distance_panel(ax, dist_tab, summary, E1, E2, g0, boxes, noise_max, delta, nums=None):
    """Panel (c): debiased Hellinger distance to the c-measures vs box side at the paper's γ: the paired
    half-sample curves of fig5.json ``refs_paired`` (percentile bands) when present, else the split-half ones."""
    styles = {
        ("5a", "E1"): ("a", COLORS[0], "o", "-"),
        ("5a", "E2"): ("a", COLORS[0], "s", "--"),
        ("5b", "E1"): ("b", COLORS[1], "o", "-"),
        ("5b", "E2"): ("b", COLORS[1], "s", "--"),
        ("E2", "E1"): (None, "0.45", "^", "-."),
    }
    rec = (nums or {}).get("refs_paired") or {}
    curves = (rec.get("curves") or {}).get("ours")
    if curves:
        x = np.asarray(rec["boxes"], dtype=float)
        for c in curves:
            s, col, mk, ls = styles[(c["set"], c["ref"])]
            d, lo, hi = (np.asarray(c[k], dtype=float) for k in ("d", "d_lo", "d_hi"))
            Eref = E1 if c["ref"] == "E1" else E2
            if s is None:
                lab = f"$\\mu_c^{{{E2:g}}}$ vs $\\mu_c^{{{E1:g}}}$"
            else:
                row = summary[(summary["gamma"] == g0) & (summary["set"] == s) & (summary["ref"] == c["ref"])]
                sw = (
                    f"; SW$_1$={format_value_err(row['sw1'].iloc[0], row['sw1_err'].iloc[0], sep='±')}"
                    if len(row)
                    else ""
                )
                lab = f"Fig. 5{s} vs $\\mu_c^{{{Eref:g}}}$" + sw
            ax.errorbar(x, d, yerr=[d - lo, hi - d], color=col, marker=mk, ms=4, lw=1.3, ls=ls, capsize=2, label=lab)
        title = f"(c) distance to the c-measures, $\\gamma={g0:g}$ ({int(rec['level'] * 100)} % paired bands)"
    else:
        for (s, ref), (short, col, mk, ls) in styles.items():
            tab = (
                dist_tab[dist_tab["set"] == "cm_E2"]
                if short is None
                else dist_tab[(dist_tab["gamma"] == g0) & (dist_tab["set"] == short) & (dist_tab["ref"] == ref)]
            )
            if len(tab):
                name = (
                    f"$\\mu_c^{{{E2:g}}}$ vs $\\mu_c^{{{E1:g}}}$"
                    if short is None
                    else f"Fig. {s} vs $\\mu_c^{{{E1 if ref == 'E1' else E2:g}}}$"
                )
                _debiased(ax, tab, f"{name} (m={int(tab['m'].iloc[0])}, split halves)", col, mk, ls, noise_max)
        title = f"(c) distance to the c-measures vs scale, $\\gamma={g0:g}$ (1σ split-half bands)"
    ax.axhline(delta, color="k", lw=0.8, ls=":")
    _box_axis(ax, boxes)
    ax.set_ylim(0, 1.3 * ax.get_ylim()[1])  # room for the legend
    ax.set_ylabel("debiased Hellinger $\\sqrt{H_{PQ}^2 - H_{\\rm noise}^2}$")
    ax.set_title(title, fontsize=10, loc="left")
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(True, which="major", alpha=0.3)


def _agreement_panel(ax, dist_tab, summary, nums, per_gamma, E1, boxes, noise_max, delta):
    """Panel (d): Fig. 5a vs μ_c^{E1} at every γ, the paired half-sample curves (fig5.json ``panel_d``) with
    their percentile bands and the agreement scales ε*_δ with their intervals; the split-half curves (1σ) when
    the paired record is missing (tiny scale)."""
    rec = nums.get("panel_d") or {}
    fmt = lambda e: f"{e:.3g}" if e is not None and np.isfinite(e) else "none"
    if "curves" in rec:
        x = np.asarray(rec["boxes"], dtype=float)
        for i, c in enumerate(rec["curves"]):
            col = COLORS[(i + 2) % len(COLORS)]
            d, lo, hi = (np.asarray(c[k], dtype=float) for k in ("d", "d_lo", "d_hi"))
            ok = np.asarray(c["informative"], dtype=bool)
            e, (elo, ehi) = c["eps_delta"], c["eps_delta_interval"]
            lab = (
                f"$\\gamma={c['gamma']:g}$, $t^*={c['t_star']:.1f}$ ({c['n_a']} pts): "
                f"$\\varepsilon^*_\\delta$={fmt(e)} [{fmt(elo)}, {fmt(ehi)}]"
            )
            ax.errorbar(
                x[ok],
                d[ok],
                yerr=[d[ok] - lo[ok], hi[ok] - d[ok]],
                color=col,
                marker="o",
                ms=4,
                lw=1.3,
                capsize=2,
                label=lab,
            )
            if (~ok).any():
                ax.plot(x[~ok], d[~ok], color=col, marker="o", ms=3, lw=0, mfc="none", alpha=0.6)
            if e is not None:
                ax.axvline(e, color=col, ls=":", lw=1.2)
        title = f"(d) convergence with $t^*$ ({int(rec['level'] * 100)} % paired bands)"
    else:
        for i, g in enumerate(sorted(per_gamma)):
            tab = dist_tab[(dist_tab["gamma"] == g) & (dist_tab["set"] == "a") & (dist_tab["ref"] == "E1")]
            if not len(tab):
                continue
            row = summary[(summary["gamma"] == g) & (summary["set"] == "a") & (summary["ref"] == "E1")].iloc[0]
            col = COLORS[(i + 2) % len(COLORS)]
            _debiased(
                ax,
                tab,
                f"$\\gamma={g:g}$, $t^*={per_gamma[g]['t_star']:.1f}$: $\\varepsilon^*_\\delta$="
                f"{fmt(row['agreement_scale_debiased'])} (split halves, 1σ)",
                col,
                "o",
                "-",
                noise_max,
            )
        title = f"(d) convergence with relaxation time $t^*$ (common m = {nums['m_common']})"
    ax.axhline(delta, color="k", lw=0.8, ls=":")
    ax.text(max(boxes), delta, f" $\\delta$ = {delta:g}", va="bottom", ha="right", fontsize=8)
    _box_axis(ax, boxes)
    ax.set_ylim(0, 1.25 * ax.get_ylim()[1])  # room for the legend
    ax.set_ylabel(f"debiased Hellinger, Fig. 5a vs $\\mu_c^{{{E1:g}}}$")
    ax.set_title(title, fontsize=10, loc="left")
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, which="major", alpha=0.3)
