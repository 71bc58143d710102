"""Figure of the escape-criterion study ``resc`` (draws derived tables; computes nothing)."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels
from hhscatter.reproduction.verdicts import row_bound

COLORS = ("#1b7837", "#2166ac", "#b2182b", "#762a83", "#e08214")


def _xaxis(ax, radii):
    ax.set_xscale("log")
    ticks = [r - 1.0 for r in radii]
    ax.set_xticks(ticks)
    ax.set_xticklabels([f"{r:g}" for r in radii])
    ax.minorticks_off()
    ax.set_xlim(min(ticks) / 1.6, max(ticks) * 1.6)
    ax.set_xlabel(r"escape radius $r_{esc}$  (log scale in $r_{esc}-1$)")


DX = 0.035  # marker offset in log10(r_esc − 1)


def _logx(r, off=0.0):
    """Abscissa of the log axis in r_esc − 1, shifted by ``off`` decades (marker offsets)."""
    return (np.asarray(r, dtype=float) - 1.0) * 10**off


def _panel_kappa_shift(a, kappa, energies, radii, col, r_ref):
    """Panel (a): relative κ shift against r_esc, with the MLE and the paper's-rule cross-checks."""
    dx = DX
    for i, E in enumerate(energies):
        k = kappa[kappa.energy == E].sort_values("r_esc")
        kr = float(k[k.r_esc == r_ref].kappa.iloc[0])
        off = (i - (len(energies) - 1) / 2) * dx
        a.errorbar(
            _logx(k.r_esc, off),
            100 * k.kappa_shift / kr,
            100 * k.kappa_shift_err / kr,
            fmt="o-",
            color=col[E],
            ms=5,
            capsize=3,
            lw=1.4,
            label=f"E = {E:.2f}  (κ = {kr:.4f} at r_esc = {r_ref:g})",
        )
        a.errorbar(
            _logx(k.r_esc, off + dx / 3),
            100 * k.mle_shift / kr,
            100 * k.mle_shift_err / kr,
            fmt="s",
            mfc="none",
            color=col[E],
            ms=4,
            capsize=2,
            lw=0.7,
            alpha=0.6,
        )
        lsq_ref = float(k[k.r_esc == r_ref].kappa_lsq.iloc[0])
        if np.isfinite(lsq_ref) and lsq_ref > 0:
            # its errors (±3–8 %: window spread) would hide the panel; they are in the table
            a.plot(
                _logx(k.r_esc, off - dx / 3),
                100 * (k.kappa_lsq / lsq_ref - 1),
                "D",
                mfc="none",
                color=col[E],
                ms=3.5,
                alpha=0.5,
            )
    a.axhline(0, color="0.4", lw=0.8)
    a.set_ylim(*_kappa_shift_ylim(kappa, energies, r_ref))
    _xaxis(a, radii)
    a.set_ylabel(r"$\kappa(r_{esc})/\kappa(" + f"{r_ref:g}" + r") - 1$  [%]")
    a.set_title("(a) escape rate vs escape radius (same ICs for every $r_{esc}$)", fontsize=10)
    a.plot([], [], "o-", color="0.3", label="slope of paired log[P(t)/P$_{ref}$(t)] (±1σ)")
    a.plot([], [], "s", mfc="none", color="0.3", alpha=0.6, label="difference of MLEs, common window")
    a.plot(
        [],
        [],
        "D",
        mfc="none",
        color="0.3",
        alpha=0.45,
        label="mean of 4 LSQ fits, own windows (paper; ±3–8 %, not drawn)",
    )
    a.legend(fontsize=6.5, loc="lower left", ncol=1)
    a.grid(alpha=0.3)


def _kappa_shift_ylim(kappa, energies, r_ref):
    """y-range of panel (a) in %: the ±1σ bars and the cross-check markers inside, with room for the legend."""
    main = [
        100
        * (kappa.kappa_shift + sgn * kappa.kappa_shift_err)
        / kappa.energy.map(
            {E: float(kappa[(kappa.energy == E) & (kappa.r_esc == r_ref)].kappa.iloc[0]) for E in energies}
        )
        for sgn in (-1, 1)
    ]
    others = []
    for E in energies:  # the cross-check markers are drawn too: keep them inside the panel
        k = kappa[kappa.energy == E]
        kr = float(k[k.r_esc == r_ref].kappa.iloc[0])
        lr = float(k[k.r_esc == r_ref].kappa_lsq.iloc[0])
        others += list(100 * (k.mle_shift / kr)) + list(100 * (k.kappa_lsq / lr - 1))
    lo_a = float(np.nanmin([np.nanmin(main[0]), *others]))
    hi_a = float(np.nanmax([np.nanmax(main[1]), *others]))
    pad = 0.6 * max(hi_a - lo_a, 1.0)
    return lo_a - pad, hi_a + 0.5 * pad


def _panel_time_shift(b, kappa, energies, radii, col, r_ref):
    """Panel (b): mean flight time from r_ref to r_esc and the delay of P(t) at the window start."""
    for E in energies:
        k = kappa[kappa.energy == E].sort_values("r_esc")
        b.errorbar(
            _logx(k.r_esc),
            k.flight_mean,
            k.flight_err,
            fmt="o-",
            color=col[E],
            ms=5,
            capsize=3,
            label=f"E = {E:.2f}: mean flight time from r = {r_ref:g}",
        )
        b.plot(
            _logx(k.r_esc),
            k.time_shift,
            "s--",
            mfc="none",
            color=col[E],
            ms=6,
            lw=0.9,
            label=f"E = {E:.2f}: delay of P(t) at the window start",
        )
    _xaxis(b, radii)
    b.set_ylabel("time delay  [time units]")
    b.set_title(f"(b) delay of the escape time from r = {r_ref:g} to " + r"$r_{esc}$", fontsize=10)
    b.legend(fontsize=7, loc="upper left")
    b.grid(alpha=0.3)


def zero_count_bounds(n_escaped) -> np.ndarray:
    """The one-sided 95 % upper bounds drawn for return counts of 0 out of ``n_escaped`` escaped orbits: the bound
    the comparison table prints (:func:`hhscatter.reproduction.verdicts.row_bound`), never a two-sided interval."""
    return np.array([row_bound({"ours": 0.0, "n": int(n)})["upper"] for n in n_escaped], dtype=float)


def _panel_returns(c, returns, lyapunov, energies, radii, col):
    """Panel (c): share of escaped orbits returning inside r < 1 (one-sided 95 % upper bounds at zero counts)."""
    dx = DX
    ymin = 1.0
    for i, E in enumerate(energies):
        r = returns[returns.energy == E].sort_values("r_esc")
        off = (i - (len(energies) - 1) / 2) * dx
        pos = r.n_returned > 0
        if pos.any():
            rp = r[pos]
            c.errorbar(
                _logx(rp.r_esc, off),
                rp.frac,
                [rp.frac - rp.lo, rp.hi - rp.frac],
                fmt="o-",
                color=col[E],
                ms=5,
                capsize=3,
                label=f"E = {E:.2f}",
            )
            ymin = min(ymin, float(rp.lo[rp.lo > 0].min()) if (rp.lo > 0).any() else ymin)
        z = r[~pos]
        if len(z):
            bound = zero_count_bounds(z.n_escaped)
            c.errorbar(
                _logx(z.r_esc, off),
                bound,
                yerr=0.35 * bound,
                uplims=True,
                fmt="v",
                color=col[E],
                ms=5,
                mfc="none",
                capsize=0,
                label=None if pos.any() else f"E = {E:.2f}",
            )
            ymin = min(ymin, float(bound.min()) * 0.4)
        ly = lyapunov[np.isclose(lyapunov.energy, E)]
        if len(ly):  # radial extent of the Lyapunov orbit (the exact boundary of Ω) as a bar at the top
            yb = 0.45 * 0.45**i
            c.plot(
                [float(ly.r_min.iloc[0]) - 1, float(ly.r_max.iloc[0]) - 1],
                [yb, yb],
                color=col[E],
                lw=4,
                solid_capstyle="butt",
                alpha=0.6,
            )
            c.text(
                float(ly.r_max.iloc[0]) - 1,
                yb,
                f"  Lyapunov orbit, E = {E:.2f}",
                va="center",
                fontsize=6.5,
                color=col[E],
            )
    c.set_yscale("log")
    c.set_ylim(max(ymin * 0.5, 1e-8), 1.0)
    _xaxis(c, radii)
    c.set_ylabel(r"fraction returning inside $r<1$ after escape")
    c.set_title("(c) returns after the first crossing of $r_{esc}$", fontsize=10)
    c.plot([], [], "v", mfc="none", color="0.3", label="none seen: one-sided\n95 % upper bound (as the table)")
    c.legend(fontsize=7.5, loc="center right", bbox_to_anchor=(1.0, 0.42))
    c.grid(alpha=0.3, which="both")


def _panel_channels(d, channels, energies, col, r_ref):
    """Panel (d): escape share per exit channel (all, early, late) at r_ref against the symmetric 1/3."""
    ch = channels[np.isclose(channels.r_esc, r_ref)]
    subsets = [s for s in ("all", "early", "late") if s in set(ch.subset)]
    markers = {"all": "o", "early": "^", "late": "s"}
    width = 0.8
    n_e, n_s = len(energies), len(subsets)
    for i, E in enumerate(energies):
        for j, s in enumerate(subsets):
            q = ch[np.isclose(ch.energy, E) & (ch.subset == s)].sort_values("channel")
            off = -width / 2 + width * (i * n_s + j + 0.5) / (n_e * n_s)
            p = float(q.p_value.iloc[0])
            d.errorbar(
                q.channel + off,
                q.frac,
                [q.frac - q.lo, q.hi - q.frac],
                fmt=markers[s],
                color=col[E],
                ms=4.5,
                capsize=2,
                mfc=col[E] if s == "all" else "none",
                lw=1,
                label=f"E = {E:.2f}, {s} (n = {int(q.n.iloc[0])}, χ² p = {p:.2f})",
            )
    d.plot([], [], " ", label="early/late: escape before/after the κ-window start")
    d.axhline(1 / 3, color="k", lw=1, ls="--", label="1/3 (three-fold symmetry)")
    d.set_xticks(range(3))
    d.set_xticklabels([r"channel 0 ($\varphi=\pi/2$)", r"1 ($7\pi/6$)", r"2 ($11\pi/6$)"])
    d.set_ylabel("fraction of escapes")
    d.set_title(r"(d) exit channels at $r_{esc}$" + f" = {r_ref:g}", fontsize=10)
    d.legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.13))  # below: off the data and ticks
    lo = float(ch.lo.min())
    hi = float(ch.hi.max())
    pad = max(hi - lo, 0.002)
    d.set_ylim(lo - 0.2 * pad, hi + 0.2 * pad)
    d.grid(alpha=0.3, axis="y")


def plot_resc(kappa, returns, channels, lyapunov, path, *, r_ref=1.03, scale=""):
    """plot_resc(kappa, returns, channels, lyapunov, path, r_ref=1.03) -> None; writes resc.png.

    Panels: (a) relative κ shift κ(r_esc)/κ(r_ref) − 1 per energy (slope of
    the paired log-survival ratio, ±1σ; open markers: difference of MLEs on
    the common window and the paper's rule with own windows); (b) mean
    flight time from r_ref to r_esc and the delay of P(t); (c) fraction of escaped orbits
    that return inside r < 1 (Wilson ±1σ; a count of 0 drawn at its one-sided
    95 % upper bound, the number the table prints), with the radial extent of each energy's Lyapunov orbit;
    (d) escape fraction per exit channel (all, early t ≤ τ0, late t > τ0) at
    r_ref with the 1/3 of the three-fold symmetry.  Inputs are the study's
    derived tables (pandas DataFrames).
    """
    plt = agg_pyplot()
    energies = sorted(kappa.energy.unique())
    radii = sorted(kappa.r_esc.unique())
    col = {E: COLORS[i % len(COLORS)] for i, E in enumerate(energies)}
    fig, axs = plt.subplots(2, 2, figsize=(10.5, 8.0), constrained_layout=True)
    (a, b), (c, d) = axs
    _panel_kappa_shift(a, kappa, energies, radii, col, r_ref)
    _panel_time_shift(b, kappa, energies, radii, col, r_ref)
    _panel_returns(c, returns, lyapunov, energies, radii, col)
    _panel_channels(d, channels, energies, col, r_ref)
    fig.suptitle(f"Escape criterion r > r_esc, conservative Hénon–Heiles (disk ICs; scale '{scale}')", fontsize=11)
    fig.savefig(path, dpi=150)
    save_panels(fig, path, dpi=200)  # each panel legible at a page's full width (≈ 1000 px)
    plt.close(fig)
