"""Figure of the study ``basins`` (draws the derived tables; computes nothing)."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels

#: colour per outcome code 0, 1, 2 (exit channels), 3 (settled), 4 (censored: still inside at t_max); forbidden
#: cells white
COLORS = ("#d7301f", "#2171b5", "#238b45", "#fdb863", "#3f3f3f")
NAMES = ("exit 0", "exit 1", "exit 2", "settled", "censored")


def _image(ax, labels, extent, cmap, norm):
    img = np.ma.masked_less(labels, 0)
    return ax.imshow(img, origin="lower", extent=extent, cmap=cmap, norm=norm, interpolation="nearest")


def plot_basins(maps, zooms, entropy, uncertainty, numbers, path, *, scale="", local=None, scan=None):
    """Write the study's figures: ``path`` (basins.png) and three siblings basins_<part>.png.

    basins.png: the basin map of each (E0, γ), three per row, with a discrete legend; basins_zoom.png: one
    boundary region at two magnifications per γ listed; basins_measures.png: (a) f(ε) on log–log axes with the
    fitted power laws, (b) S_b and S_bb against γ with ln 2, (c) d = 2 − α against γ, (d) S_b and S_bb at
    fixed box sides on every grid (like for like across resolutions); basins_scale.png (when ``local`` and
    ``scan`` are given): the local dimension d(ε) per E0, the measured against the predicted cut-off ε_c, the
    Wada fraction, and the γ = 0 energy scan. Each panel is drawn 4 in wide or more, so that it stays
    legible when the figure is shown at the page's content width.
    """
    from pathlib import Path

    from matplotlib.colors import BoundaryNorm, ListedColormap

    plt = agg_pyplot()
    path = Path(path)
    cmap = ListedColormap(COLORS).with_extremes(bad="white")
    norm = BoundaryNorm(np.arange(-0.5, 5.5), cmap.N)
    energies = sorted(maps.energy.unique())
    gammas = sorted(maps.gamma.unique())
    n = int(numbers["grid"])
    tail = f"{' — ' + scale if scale else ''}"
    pairs = [(E, g) for E in energies for g in gammas]
    ncol = min(3, len(pairs))
    nrow = -(-len(pairs) // ncol)
    fig, axs = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 4.0 * nrow + 0.6), constrained_layout=True, squeeze=False)
    _map_panels(axs.ravel(), maps, pairs, n, numbers["extent"], cmap, norm)
    _legend(fig)
    fig.suptitle(
        f"Exit basins on the section $\\dot r = 0$, $\\dot\\varphi > 0$ ({n}×{n} cells, $r_{{esc}}=1.5$){tail}",
        fontsize=12,
    )
    fig.savefig(path, dpi=100)
    plt.close(fig)
    zg, zf = sorted(zooms.gamma.unique()), sorted(zooms.factor.unique())
    fig, axs = plt.subplots(
        len(zg), len(zf), figsize=(4.6 * len(zf), 4.2 * len(zg) + 0.6), constrained_layout=True, squeeze=False
    )
    _zoom_panels(axs, zooms, zg, zf, numbers["zoom_centre"], cmap, norm)
    _legend(fig)
    fig.suptitle(f"Zooms into one boundary region{tail}", fontsize=12)
    fig.savefig(path.with_name(path.stem + "_zoom.png"), dpi=100)
    plt.close(fig)
    per = numbers["per_point"]
    fig, axs = plt.subplots(2, 2, figsize=(11, 9), constrained_layout=True)
    _panel_uncertainty(axs[0, 0], uncertainty, per)
    _panel_entropy(axs[0, 1], per, energies, gammas)
    _panel_dimension(axs[1, 0], per, energies)
    _panel_entropy_by_box(axs[1, 1], numbers.get("entropy_by_box") or [])
    fig.suptitle(f"Fractality measures{tail}", fontsize=12)
    fig.savefig(path.with_name(path.stem + "_measures.png"), dpi=100)
    save_panels(fig, path.with_name(path.stem + "_measures.png"), dpi=180)  # each at a page's full width
    plt.close(fig)
    if local is not None and scan is not None:
        fig, axs = plt.subplots(3, 2, figsize=(11, 13), constrained_layout=True)
        _scale_panels(axs, energies, gammas, local, scan, numbers)
        fig.suptitle(f"Scale-dependent dimension, cut-off, Wada and the γ = 0 energy scan{tail}", fontsize=12)
        fig.savefig(path.with_name(path.stem + "_scale.png"), dpi=100)
        save_panels(fig, path.with_name(path.stem + "_scale.png"), dpi=180)  # the twin-axes panel stays one
        plt.close(fig)


def _legend(fig):
    from matplotlib.patches import Patch

    fig.legend(
        handles=[Patch(color=c, label=nm) for c, nm in zip(COLORS, NAMES)]
        + [Patch(facecolor="white", edgecolor="0.6", label="forbidden ($V \\geq E_0$)")],
        loc="outside lower center",
        ncol=6,
        fontsize=10,
    )


def _map_panels(axes, maps, pairs, n, ext, cmap, norm):
    """The basin map of each (E0, γ) in ``pairs``, one panel each (spare panels hidden)."""
    for ax, (E, g) in zip(axes, pairs):
        lab = maps[(maps.energy == E) & (maps.gamma == g)].label.to_numpy().reshape(n, n)
        _image(ax, lab, ext, cmap, norm)
        ax.set_title(f"$E_0={E:g}$, $\\gamma={g:g}$", fontsize=11)
        ax.set_aspect("equal")
        ax.set_xlabel("$x$")
        ax.set_ylabel("$y$")
    for ax in axes[len(pairs) :]:
        ax.set_visible(False)


def _zoom_panels(axs, zooms, zg, zf, centre, cmap, norm):
    """The zooms of one boundary region: one row per γ, one column per magnification."""
    cx, cy = centre
    for i, g in enumerate(zg):
        for j, f in enumerate(zf):
            ax = axs[i, j]
            z = zooms[(zooms.gamma == g) & (zooms.factor == f)]
            m = int(round(np.sqrt(len(z))))
            e = [float(z[c].iloc[0]) for c in ("x0", "x1", "y0", "y1")]
            _image(ax, z.label.to_numpy().reshape(m, m), e, cmap, norm)
            ax.set_title(f"×{f:g} at ({cx:.3f}, {cy:.3f}), $\\gamma={g:g}$", fontsize=10)
            ax.set_xlabel("$x$")
            ax.set_ylabel("$y$")
            ax.ticklabel_format(useOffset=False)
            ax.tick_params(labelsize=8)


def _panel_entropy_by_box(ax, recs):
    """S_b and S_bb at fixed box sides (position units) at γ = 0, one line per (E0, grid): like for like across
    map resolutions."""
    groups = {}
    for r in recs:
        if r["gamma"] == 0:
            groups.setdefault((r["E0"], r["grid"], r.get("map", "map")), []).append(r)
    for k, ((E, grid, which), rs) in enumerate(sorted(groups.items())):
        rs = sorted(rs, key=lambda r: r["box_side"])
        s = [r["box_side"] for r in rs]
        c = f"C{k}"
        ax.errorbar(
            s,
            [r["S_b"] for r in rs],
            yerr=[r["S_b_err"] for r in rs],
            fmt="o-",
            ms=4,
            color=c,
            label=f"$S_b$, $E_0={E:g}$, {grid}² ({which})",
        )
        ax.errorbar(
            s,
            [r["S_bb"] for r in rs],
            yerr=[r["S_bb_err"] for r in rs],
            fmt="s--",
            ms=4,
            color=c,
            mfc="none",
            label=f"$S_{{bb}}$, $E_0={E:g}$, {grid}²",
        )
    ax.axhline(np.log(2), color="k", lw=0.8, ls=":", label="ln 2")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("box side $s$ (position units)")
    ax.set_ylabel("basin entropy at $\\gamma = 0$")
    ax.set_title("(d) $S_b$, $S_{bb}$ at fixed box sides", fontsize=10)
    ax.legend(fontsize=7)


def _panel_uncertainty(ax, uncertainty, per):
    """Panel (a): f(ε) on log–log axes with the fitted power laws over their ε ranges; a colour per γ (viridis), a
    marker and line style per E0 (no colour repeats however many points)."""
    from matplotlib import colormaps

    gs = sorted(uncertainty.gamma.unique())
    es = sorted(uncertainty.energy.unique())
    cmap = colormaps["viridis"]
    for (E, g), u in uncertainty.groupby(["energy", "gamma"]):
        ok = u.k > 0
        err = np.vstack([u.f[ok] - u.f_lo[ok], u.f_hi[ok] - u.f[ok]])
        colour = cmap(0.9 * gs.index(g) / max(1, len(gs) - 1))
        marker = "osD^v"[es.index(E) % 5]
        line = ax.errorbar(
            u.eps[ok], u.f[ok], yerr=err, fmt=marker, ms=3.5, color=colour, label=f"$E_0={E:g}, \\gamma={g:g}$"
        )
        p = next(q for q in per if q["energy"] == E and q["gamma"] == g)
        if p["alpha"]:
            lo, hi = p["alpha_fit_range"]
            xs = np.geomspace(lo, hi, 20)
            f_hi = float(u.f[u.eps == u.eps[(u.eps >= lo)].min()].iloc[0])
            ls = ("-", "--", ":", "-.")[es.index(E) % 4]
            ax.plot(xs, f_hi * (xs / xs[0]) ** p["alpha"]["value"], ls, color=line[0].get_color(), lw=0.9)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("perturbation $\\varepsilon$")
    ax.set_ylabel("uncertain fraction $f(\\varepsilon)$")
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.14))  # below: the data fill the box


def _panel_entropy(ax, per, energies, gammas):
    """Panel (b): S_b and S_bb against γ at the headline box, with ln 2."""
    hb = per[0]["box_headline"]
    gx = np.array([max(g, 1e-4) for g in gammas])
    for E in energies:
        rows = [q for q in per if q["energy"] == E]
        sb = [q["S_b"]["value"] if q["S_b"] else np.nan for q in rows]
        sbb = [q["S_bb"]["value"] if q["S_bb"] else np.nan for q in rows]
        ax.plot(gx, sb, "o-", label=f"$S_b$, $E_0={E:g}$")
        ax.plot(gx, sbb, "s--", label=f"$S_{{bb}}$, $E_0={E:g}$")
    ax.axhline(np.log(2), color="k", lw=0.8, ls=":", label="ln 2")
    ax.set_xscale("log")
    ax.set_xlabel("$\\gamma$ ($\\gamma=0$ drawn at $10^{-4}$)")
    ax.set_ylabel(f"basin entropy (box {hb}×{hb} cells)")
    ax.legend(fontsize=6)


def _panel_dimension(ax, per, energies):
    """Panel (c): the uncertainty dimension d = 2 − α against γ."""
    for E in energies:
        rows = [q for q in per if q["energy"] == E and q["d"]]
        ax.errorbar(
            [max(q["gamma"], 1e-4) for q in rows],
            [q["d"]["value"] for q in rows],
            yerr=[q["d"]["err"] for q in rows],
            fmt="o-",
            capsize=2,
            label=f"$E_0={E:g}$",
        )
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="smooth boundary (d = 1)")
    ax.set_xscale("log")
    ax.set_xlabel("$\\gamma$ ($\\gamma=0$ drawn at $10^{-4}$)")
    ax.set_ylabel("uncertainty dimension $d = 2 - \\alpha$")
    ax.legend(fontsize=7)


def _scale_panels(axs, energies, gammas, local, scan, numbers):
    """Scale-dependent dimension per E0, cut-off prediction, like-for-like Wada and the γ = 0 energy scan."""
    import matplotlib.pyplot as plt

    cm = plt.get_cmap("viridis")
    for k, E in enumerate(energies[:2]):
        _panel_local_dimension(axs[0, k], E, gammas, local, cm)
    _panel_cutoff(axs[1, 0], energies, numbers)
    _panel_wada(axs[1, 1], energies, numbers["per_point"])
    E_b = numbers["E_b"]["value"]
    _panel_scan_entropy(axs[2, 0], scan, E_b)
    _panel_scan_dimension(axs[2, 1], scan, E_b)
    if len(energies) < 2:
        axs[0, 1].set_visible(False)


def _panel_local_dimension(ax, E, gammas, local, cm):
    """The local dimension d(ε) = 2 − α(ε) against ε at one E0, one line per γ (points with σ < 0.3)."""
    for i, g in enumerate(gammas):
        t = local[(local.energy == E) & (local.gamma == g) & np.isfinite(local.d) & (local.d_err < 0.3)]
        ax.errorbar(
            t.eps_mid,
            t.d,
            yerr=t.d_err,
            fmt="o-",
            ms=3,
            lw=0.8,
            capsize=2,
            color=cm(i / max(len(gammas) - 1, 1)),
            label=f"$\\gamma={g:g}$",
        )
    ax.axhline(1.0, color="k", lw=0.8, ls=":")
    ax.set_xscale("log")
    ax.set_ylim(0.8, 2.05)
    ax.set_xlabel("resolution $\\varepsilon$")
    ax.set_ylabel("local dimension $d(\\varepsilon) = 2 - \\alpha(\\varepsilon)$ (σ < 0.3)")
    ax.set_title(f"$E_0={E:g}$", fontsize=10)
    ax.legend(fontsize=6, ncol=2)


def _panel_cutoff(ax, energies, numbers):
    """The measured cut-off ε_c (or its upper bound) against the predicted band, against γ."""
    for k, E in enumerate(energies):
        recs = [r for r in numbers.get("cutoff_prediction", []) if r["E0"] == E]
        if not recs:
            continue
        g = np.array([r["gamma"] for r in recs])
        pred = np.array([r["eps_c_predicted"] for r in recs])
        lo = np.array([r["eps_c_predicted_interval"][0] for r in recs])
        hi = np.array([r["eps_c_predicted_interval"][1] for r in recs])
        c = f"C{k}"
        ax.fill_between(g, lo, hi, color=c, alpha=0.2)
        ax.plot(g, pred, "--", color=c, label=f"predicted, $E_0={E:g}$")
        for r in recs:
            if r["detected"]:
                lo_m, hi_m = r["eps_c_interval"]
                ax.errorbar(
                    [r["gamma"]],
                    [r["eps_c"]],
                    yerr=[[r["eps_c"] - lo_m], [hi_m - r["eps_c"]]],
                    fmt="o",
                    color=c,
                    capsize=2,
                )
            elif r["eps_c_interval"]:
                ax.plot([r["gamma"]], [r["eps_c_interval"][1]], "v", color=c, mfc="none")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(1e-12, 1.0)  # the measured range of ε; smaller predictions lie below the frame
    ax.set_xlabel("$\\gamma$")
    ax.set_ylabel("cut-off $\\varepsilon_c$ (o measured, ▽ upper bound)")
    ax.legend(fontsize=6)


def _panel_wada(ax, energies, per):
    """Wada fraction W(r) against γ: exit basins with settled masked, against all basins."""
    for k, E in enumerate(energies):
        rows = [q for q in per if q["energy"] == E]
        gx = [max(q["gamma"], 1e-4) for q in rows]
        ax.plot(
            gx,
            [q["wada"]["W_at_r"] for q in rows],
            "s--",
            color=f"C{k}",
            mfc="none",
            label=f"all basins (settled a basin), $E_0={E:g}$",
        )
        ax.plot(
            gx,
            [q["wada_exits"]["W_at_r"] if q["wada_exits"] else np.nan for q in rows],
            "o-",
            color=f"C{k}",
            label=f"exit basins (settled masked), $E_0={E:g}$",
        )
    ax.axhline(0.99, color="k", lw=0.8, ls=":", label="Wada threshold")
    ax.set_xscale("log")
    ax.set_xlabel("$\\gamma$ ($\\gamma=0$ drawn at $10^{-4}$)")
    ax.set_ylabel("Wada fraction $W(r)$")
    ax.legend(fontsize=5)


def _panel_scan_entropy(ax, scan, E_b):
    """The γ = 0 energy scan: S_b and S_bb against E0, with ln 2 and fig2's break energy E_b."""
    ax.errorbar(scan.energy, scan.S_b, yerr=scan.S_b_err, fmt="o-", ms=3, label="$S_b$")
    ax.errorbar(scan.energy, scan.S_bb, yerr=scan.S_bb_err, fmt="s-", ms=3, label="$S_{bb}$")
    ax.axhline(np.log(2), color="k", lw=0.8, ls=":", label="ln 2")
    ax.axvline(E_b, color="0.4", lw=0.8, ls="--", label="$E_b$ (fig2)")
    ax.set_xlabel("$E_0$ ($\\gamma = 0$)")
    ax.set_ylabel("basin entropy")
    ax.legend(fontsize=6)


def _panel_scan_dimension(ax, scan, E_b):
    """The γ = 0 energy scan: d = 2 − α and the decision rate λ (and κ/α when present) against E0."""
    ax.errorbar(scan.energy, 2 - scan.alpha, yerr=scan.alpha_err, fmt="o-", ms=3, color="C2", label="$d = 2 - \\alpha$")
    ax.set_ylabel("uncertainty dimension $d$", color="C2")
    ax.axvline(E_b, color="0.4", lw=0.8, ls="--")
    ax.set_xlabel("$E_0$ ($\\gamma = 0$)")
    ax2 = ax.twinx()
    ax2.errorbar(
        scan.energy, scan.lam, yerr=scan.lam_err, fmt="s--", ms=3, color="C3", label="$\\lambda$, decision rate"
    )
    if "lam_kg" in scan:
        ax2.errorbar(
            scan.energy,
            scan.lam_kg,
            yerr=scan.lam_kg_err,
            fmt="^:",
            ms=3,
            color="C1",
            label="$\\kappa/\\alpha$ (Kantz–Grassberger, $\\kappa$ of fig2)",
        )
    ax2.legend(fontsize=6, loc="lower right")
    ax2.set_ylabel("decision rate $\\lambda$ (1/time)", color="C3")
