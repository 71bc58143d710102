"""Figure of the study ``basins`` (draws the derived tables; computes nothing)."""
from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot

#: colour per outcome code 0, 1, 2 (exit channels), 3 (settled), 4 (trapped); forbidden cells white
COLORS = ("#d7301f", "#2171b5", "#238b45", "#fdb863", "#3f3f3f")
NAMES = ("exit 0", "exit 1", "exit 2", "settled", "trapped")


def _image(ax, labels, extent, cmap, norm):
    img = np.ma.masked_less(labels, 0)
    return ax.imshow(img, origin="lower", extent=extent, cmap=cmap, norm=norm, interpolation="nearest")


def plot_basins(maps, zooms, entropy, uncertainty, numbers, path, *, scale="", local=None, scan=None):
    """plot_basins(maps, zooms, entropy, uncertainty, numbers, path) -> None; writes basins.png.

    Rows 1–2: the basin maps of each (E0, γ) with a discrete legend; row 3:
    the zoom of one boundary region at two magnifications (γ as listed);
    row 4: (a) f(ε) on log–log axes with the fitted power laws, (b) S_b and
    S_bb against γ with ln 2, (c) the uncertainty dimension d = 2 − α
    against γ; row 5 (issue 25, when ``local`` and ``scan`` are given): the
    local dimension d(ε) against ε for every γ at each E0, the measured and
    predicted cut-off ε_c against γ, the Wada fraction of the exit basins
    (settled masked) and of all basins against γ, and the γ = 0 energy scan
    (S_b, S_bb, d = 2 − α and λ against E0, with fig2's break energy E_b).
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
    extra = local is not None and scan is not None
    ncol = max(len(gammas), len(zg) * len(zf), 3, 6 if extra else 0)
    nrow = len(energies) + 2 + int(extra)
    fig = plt.figure(figsize=(3.0 * ncol, 3.0 * nrow), constrained_layout=True)
    gs = fig.add_gridspec(nrow, ncol)
    _map_rows(fig, gs, maps, energies, gammas, n, ext, cmap, norm)
    _zoom_row(fig, gs, len(energies), zooms, zg, zf, numbers["zoom_centre"], cmap, norm)
    per = numbers["per_point"]
    last = nrow - 1 - int(extra)
    _panel_uncertainty(fig.add_subplot(gs[last, 0]), uncertainty, per)
    _panel_entropy(fig.add_subplot(gs[last, 1]), per, energies, gammas)
    _panel_dimension(fig.add_subplot(gs[last, 2]), per, energies)
    if extra:
        _issue25_row(fig, gs, nrow - 1, ncol, energies, gammas, local, scan, numbers)
    fig.legend(handles=[Patch(color=c, label=nm) for c, nm in zip(COLORS, NAMES)] +
               [Patch(facecolor="white", edgecolor="0.6", label="forbidden ($V \\geq E_0$)")],
               loc="outside lower center", ncol=6, fontsize=9)
    fig.suptitle(f"Exit basins on the section $\\dot r = 0$, $\\dot\\varphi > 0$ "
                 f"({n}×{n} cells, $r_{{esc}}=1.5$){' — ' + scale if scale else ''}", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _map_rows(fig, gs, maps, energies, gammas, n, ext, cmap, norm):
    """Rows 1–2: the basin map of each (E0, γ), one row per E0."""
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


def _zoom_row(fig, gs, row, zooms, zg, zf, centre, cmap, norm):
    """Row 3: the zooms of one boundary region, per γ and magnification."""
    cx, cy = centre
    for j, (g, f) in enumerate((g, f) for g in zg for f in zf):
        ax = fig.add_subplot(gs[row, j])
        z = zooms[(zooms.gamma == g) & (zooms.factor == f)]
        m = int(round(np.sqrt(len(z))))
        e = [float(z[c].iloc[0]) for c in ("x0", "x1", "y0", "y1")]
        _image(ax, z.label.to_numpy().reshape(m, m), e, cmap, norm)
        ax.set_title(f"zoom ×{f:g} at ({cx:.3f}, {cy:.3f}), $\\gamma={g:g}$", fontsize=9)
        ax.set_xlabel("$x$")
        ax.ticklabel_format(useOffset=False)
        ax.tick_params(labelsize=7)


def _panel_uncertainty(ax, uncertainty, per):
    """Panel (a): f(ε) on log–log axes with the fitted power laws over their ε ranges."""
    for (E, g), u in uncertainty.groupby(["energy", "gamma"]):
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
        ax.errorbar([max(q["gamma"], 1e-4) for q in rows], [q["d"]["value"] for q in rows],
                    yerr=[q["d"]["err"] for q in rows], fmt="o-", capsize=2, label=f"$E_0={E:g}$")
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="smooth boundary (d = 1)")
    ax.set_xscale("log")
    ax.set_xlabel("$\\gamma$ ($\\gamma=0$ drawn at $10^{-4}$)")
    ax.set_ylabel("uncertainty dimension $d = 2 - \\alpha$")
    ax.legend(fontsize=7)


def _issue25_row(fig, gs, row, ncol, energies, gammas, local, scan, numbers):
    """Scale-dependent dimension, cut-off prediction, like-for-like Wada and the γ = 0 energy scan."""
    import matplotlib.pyplot as plt

    cm = plt.get_cmap("viridis")
    col = 0
    for E in energies[:2]:
        _panel_local_dimension(fig.add_subplot(gs[row, col]), E, gammas, local, cm)
        col += 1
    _panel_cutoff(fig.add_subplot(gs[row, col]), energies, numbers)
    col += 1
    _panel_wada(fig.add_subplot(gs[row, col]), energies, numbers["per_point"])
    col += 1
    E_b = numbers["E_b"]["value"]
    _panel_scan_entropy(fig.add_subplot(gs[row, col]), scan, E_b)
    col += 1
    if col < ncol:
        _panel_scan_dimension(fig.add_subplot(gs[row, col]), scan, E_b)


def _panel_local_dimension(ax, E, gammas, local, cm):
    """The local dimension d(ε) = 2 − α(ε) against ε at one E0, one line per γ (points with σ < 0.3)."""
    for i, g in enumerate(gammas):
        t = local[(local.energy == E) & (local.gamma == g) & np.isfinite(local.d) & (local.d_err < 0.3)]
        ax.errorbar(t.eps_mid, t.d, yerr=t.d_err, fmt="o-", ms=3, lw=0.8, capsize=2,
                    color=cm(i / max(len(gammas) - 1, 1)), label=f"$\\gamma={g:g}$")
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
                ax.errorbar([r["gamma"]], [r["eps_c"]], yerr=[[r["eps_c"] - lo_m], [hi_m - r["eps_c"]]],
                            fmt="o", color=c, capsize=2)
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
        ax.plot(gx, [q["wada"]["W_at_r"] for q in rows], "s--", color=f"C{k}", mfc="none",
                label=f"all basins (settled a basin), $E_0={E:g}$")
        ax.plot(gx, [q["wada_exits"]["W_at_r"] if q["wada_exits"] else np.nan for q in rows], "o-",
                color=f"C{k}", label=f"exit basins (settled masked), $E_0={E:g}$")
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
    ax.errorbar(scan.energy, 2 - scan.alpha, yerr=scan.alpha_err, fmt="o-", ms=3, color="C2",
                label="$d = 2 - \\alpha$")
    ax.set_ylabel("uncertainty dimension $d$", color="C2")
    ax.axvline(E_b, color="0.4", lw=0.8, ls="--")
    ax.set_xlabel("$E_0$ ($\\gamma = 0$)")
    ax2 = ax.twinx()
    ax2.errorbar(scan.energy, scan.lam, yerr=scan.lam_err, fmt="s--", ms=3, color="C3",
                 label="$\\lambda$, decision rate")
    if "lam_kg" in scan:
        ax2.errorbar(scan.energy, scan.lam_kg, yerr=scan.lam_kg_err, fmt="^:", ms=3, color="C1",
                     label="$\\kappa/\\alpha$ (Kantz–Grassberger, $\\kappa$ of fig2)")
    ax2.legend(fontsize=6, loc="lower right")
    ax2.set_ylabel("decision rate $\\lambda$ (1/time)", color="C3")
