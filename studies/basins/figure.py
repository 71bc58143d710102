"""Figure of the study ``basins`` (draws the derived tables; computes nothing)."""
from __future__ import annotations

import numpy as np

from hhscatter.plotting import agg_pyplot

#: colour per outcome code 0, 1, 2 (exit channels), 3 (settled), 4 (trapped); forbidden cells white
COLORS = ("#d7301f", "#2171b5", "#238b45", "#fdb863", "#3f3f3f")
NAMES = ("exit 0", "exit 1", "exit 2", "settled", "trapped")


def _image(ax, labels, extent, cmap, norm):
    img = np.ma.masked_less(labels, 0)
    return ax.imshow(img, origin="lower", extent=extent, cmap=cmap, norm=norm, interpolation="nearest")


def plot_basins(maps, zooms, entropy, uncertainty, numbers, path, *, scale=""):
    """plot_basins(maps, zooms, entropy, uncertainty, numbers, path) -> None; writes basins.png.

    Rows 1–2: the basin maps of each (E0, γ) with a discrete legend; row 3:
    the zoom of one boundary region at two magnifications (γ as listed);
    row 4: (a) f(ε) on log–log axes with the fitted power laws, (b) S_b and
    S_bb against γ with ln 2, (c) the uncertainty dimension d = 2 − α
    against γ.
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    plt = agg_pyplot()
    cmap = ListedColormap(COLORS).with_extremes(bad="white")
    norm = BoundaryNorm(np.arange(-0.5, 5.5), cmap.N)
    energies = sorted(maps.energy.unique())
    gammas = sorted(maps.gamma.unique())
    n = int(numbers["grid"])
    ext = numbers["extent"]
    zg = sorted(zooms.gamma.unique())
    zf = sorted(zooms.factor.unique())
    ncol = max(len(gammas), len(zg) * len(zf), 3)
    nrow = len(energies) + 2
    fig = plt.figure(figsize=(3.0 * ncol, 3.0 * nrow), constrained_layout=True)
    gs = fig.add_gridspec(nrow, ncol)
    for i, E in enumerate(energies):
        for j, g in enumerate(gammas):
            ax = fig.add_subplot(gs[i, j])
            lab = maps[(maps.energy == E) & (maps.gamma == g)].label.to_numpy().reshape(n, n)
            _image(ax, lab, ext, cmap, norm)
            ax.set_title(f"$E_0={E:g}$, $\\gamma={g:g}$", fontsize=10)
            ax.set_aspect("equal")
            ax.set_xlabel("$x$")
            if j == 0:
                ax.set_ylabel("$y$")
    cx, cy = numbers["zoom_centre"]
    for j, (g, f) in enumerate((g, f) for g in zg for f in zf):
        ax = fig.add_subplot(gs[len(energies), j])
        z = zooms[(zooms.gamma == g) & (zooms.factor == f)]
        m = int(round(np.sqrt(len(z))))
        e = [float(z[c].iloc[0]) for c in ("x0", "x1", "y0", "y1")]
        _image(ax, z.label.to_numpy().reshape(m, m), e, cmap, norm)
        ax.set_title(f"zoom ×{f:g} at ({cx:.3f}, {cy:.3f}), $\\gamma={g:g}$", fontsize=9)
        ax.set_xlabel("$x$")
        ax.ticklabel_format(useOffset=False)
        ax.tick_params(labelsize=7)
    per = numbers["per_point"]
    # (a) f(ε)
    ax = fig.add_subplot(gs[-1, 0])
    for k, ((E, g), u) in enumerate(uncertainty.groupby(["energy", "gamma"])):
        ok = u.k > 0
        err = np.vstack([u.f[ok] - u.f_lo[ok], u.f_hi[ok] - u.f[ok]])
        line = ax.errorbar(u.eps[ok], u.f[ok], yerr=err, fmt="o", ms=3, label=f"$E_0={E:g}, \\gamma={g:g}$")
        p = next(q for q in per if q["energy"] == E and q["gamma"] == g)
        if p["alpha"]:
            lo, hi = p["alpha_fit_range"]
            xs = np.geomspace(lo, hi, 20)
            f_hi = float(u.f[u.eps == u.eps[(u.eps >= lo)].min()].iloc[0])
            ax.plot(xs, f_hi * (xs / xs[0]) ** p["alpha"]["value"], "-", color=line[0].get_color(), lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("perturbation $\\varepsilon$")
    ax.set_ylabel("uncertain fraction $f(\\varepsilon)$")
    ax.legend(fontsize=6, ncol=1)
    # (b) S_b, S_bb against γ at the headline box
    ax = fig.add_subplot(gs[-1, 1])
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
    # (c) d = 2 − α against γ
    ax = fig.add_subplot(gs[-1, 2])
    for E in energies:
        rows = [q for q in per if q["energy"] == E and q["d"]]
        ax.errorbar([max(q["gamma"], 1e-4) for q in rows], [q["d"]["value"] for q in rows],
                    yerr=[q["d"]["err"] for q in rows], fmt="o-", capsize=2, label=f"$E_0={E:g}$")
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="smooth boundary (d = 1)")
    ax.set_xscale("log")
    ax.set_xlabel("$\\gamma$ ($\\gamma=0$ drawn at $10^{-4}$)")
    ax.set_ylabel("uncertainty dimension $d = 2 - \\alpha$")
    ax.legend(fontsize=7)
    fig.legend(handles=[Patch(color=c, label=nm) for c, nm in zip(COLORS, NAMES)] +
               [Patch(facecolor="white", edgecolor="0.6", label="forbidden ($V \\geq E_0$)")],
               loc="outside lower center", ncol=6, fontsize=9)
    fig.suptitle(f"Exit basins on the section $\\dot r = 0$, $\\dot\\varphi > 0$ "
                 f"({n}×{n} cells, $r_{{esc}}=1.5$){' — ' + scale if scale else ''}", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)
