"""Fig 3 (paper fig:energy_decay): ⟨E⟩(t) with two ribbons (3 standard deviations of E, as the paper draws it;
3 standard errors of ⟨E⟩, ours), the exponential fit, energy histograms, and the local decay exponent μ(t)
beside the fitted μ of each convention.  Plot functions draw what they are given and compute nothing."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot
from hhscatter.publish.formatting import format_value_err

E_C = 1.0 / 6.0
HIST_COLORS = ("#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02")


def plot_fig3(me, tab, hist, numbers, path, *, t_max=None):
    """plot_fig3(me, tab, hist, numbers, path) -> None; writes the two-panel Fig. 3.

    ``me``: table fig3_mean_energy (t, mean_E, lo_3sigma, hi_3sigma (± 3 standard
    deviations of E), lo_3sem, hi_3sem, fit_E, mean_E_above, n, n_above);
    ``tab``: fig3_mu_windows (kind, t_lo, t_hi, t_mid, mu, mu_err, mu_free,
    mu_free_err); ``hist``: fig3_histograms (long format, t, e_lo, e_hi,
    density_log10E); ``numbers``: fig3.json (``mu``, ``authors_convention``);
    ``t_max``: right end of the time axis (default: the last grid time).
    (a) ⟨E⟩(t) on a log axis with two ribbons, light: ± 3 standard deviations
    of the energies (the spread of the ensemble; the ribbon of the paper's
    caption), dark: ± 3 standard errors of the mean (ours; √n narrower), the
    dashed fit E0 e^{−μγt} on the fit window, E_c dotted, coloured dots at the
    histogram times; inset: histograms of log10 E at those times.  (b) local
    exponent μ (free-intercept slope of log⟨E⟩ on sliding windows) against t;
    the fitted μ of every convention of ``authors_convention.mu`` as a
    segment over the times its fit used, the paper's 0.91 over [0, 200] and
    the linear-regime value 1.
    """
    plt = agg_pyplot()
    fig, (ax, bx) = plt.subplots(
        2, 1, figsize=(6.4, 8.2), height_ratios=[2.3, 1.1], sharex=True, constrained_layout=True
    )
    ts, t_right = _energy_panel(ax, me, hist, numbers, t_max)
    _histogram_inset(ax, hist, ts)
    _mu_panel(bx, tab, numbers, t_right)
    ax.text(0.01, 0.985, "(a)", transform=ax.transAxes, va="top", fontsize=10, fontweight="bold")
    bx.text(0.01, 0.96, "(b)", transform=bx.transAxes, va="top", fontsize=10, fontweight="bold")
    fig.savefig(path, dpi=200)
    plt.close(fig)


def _energy_panel(ax, me, hist, numbers, t_max):
    """Panel (a): ⟨E⟩(t) with its two ribbons, the curve above E_c, the fit, E_c and the histogram times."""
    mu = numbers["mu"]["value"]
    mu_err = numbers["mu"]["err"]
    E0, gamma = numbers["E0"], numbers["gamma"]
    w_lo, w_hi = numbers["fit_window"]

    t = me["t"].to_numpy()
    rib = numbers["authors_convention"]["ribbon"]
    sd_pct, sem_pct = 100 * rib["max_rel_half_width_3sd"], 100 * rib["max_rel_half_width_3sem"]
    ax.fill_between(
        t,
        me["lo_3sigma"],
        me["hi_3sigma"],
        color="#9ab8de",
        alpha=0.55,
        lw=0,
        label=rf"$\pm3$ SD of $E$ (spread; the paper's ribbon): $\leq${sd_pct:.0f}% of $\langle E\rangle$",
    )
    ax.fill_between(
        t,
        me["lo_3sem"],
        me["hi_3sem"],
        color="#2f5f9e",
        alpha=0.8,
        lw=0,
        label=rf"$\pm3$ SEM of $\langle E\rangle$ (ours): $\leq${sem_pct:.2g}%, within the line",
    )
    ax.plot(t, me["mean_E"], color="#0b2f6b", lw=1.6, label=r"$\langle E\rangle(t)$, orbits inside $\Omega$")
    above = me["n_above"].to_numpy() >= 20
    ax.plot(
        t[above],
        me["mean_E_above"].to_numpy()[above],
        color="#2ca02c",
        lw=1.2,
        ls="-.",
        zorder=4,
        label=r"orbits with $E>E_c$ only",
    )
    inwin = (t >= w_lo) & (t <= w_hi)
    mu_text = format_value_err(mu, mu_err, sep=r"\pm")
    ax.plot(
        t[inwin],
        me["fit_E"].to_numpy()[inwin],
        "--",
        color="#d62728",
        lw=1.6,
        label=rf"$E_0e^{{-\mu\gamma t}}$, $\mu={mu_text}$ on [{w_lo:g}, {w_hi:g}]",
    )
    ax.plot(t[t > w_hi], me["fit_E"].to_numpy()[t > w_hi], ":", color="#d62728", lw=1.0)
    ax.axhline(E_C, color="k", ls=":", lw=0.9)
    t_right = float(t[-1] if t_max is None else t_max)
    ax.set_xlim(-0.01 * t_right, t_right)
    vis = t <= t_right
    ax.set_ylim(0.6 * float(me["mean_E"][vis].min()), 0.45)
    ax.text(0.3 * t_right, E_C * 1.04, r"$E_c=1/6$", ha="left", va="bottom", fontsize=8)
    ts = sorted(hist["t"].unique())
    for k, tk in enumerate(ts):
        i = int(np.argmin(np.abs(t - tk)))
        ax.plot(t[i], me["mean_E"].iloc[i], "o", ms=6.5, color=HIST_COLORS[k % 6], mec="k", mew=0.6, zorder=5)
    ax.set_yscale("log")
    ax.set_ylabel(r"$\langle E\rangle$")
    ax.set_title(rf"$(E_0,\gamma)=({E0:g},\,{gamma:g})$, $N={numbers['n_orbits']:,}$", fontsize=10)
    ax.legend(loc="lower left", fontsize=7.5, framealpha=0.9)
    ax.grid(True, which="major", alpha=0.3)
    return ts, t_right


def _histogram_inset(ax, hist, ts):
    """Inset of panel (a): densities in log10 E at the histogram times ``ts``."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    ins = ax.inset_axes([0.55, 0.55, 0.43, 0.42])
    for k, tk in enumerate(ts):
        h = hist[hist["t"] == tk]
        edges = np.append(h["e_lo"].to_numpy(), h["e_hi"].to_numpy()[-1])
        ins.stairs(h["density_log10E"].to_numpy(), edges, color=HIST_COLORS[k % 6], lw=1.2, fill=True, alpha=0.35)
        ins.stairs(h["density_log10E"].to_numpy(), edges, color=HIST_COLORS[k % 6], lw=1.0, label=rf"$t={tk:g}$")
    ins.axvline(E_C, color="k", ls=":", lw=0.8)
    ins.set_xscale("log")
    ins.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 3.0)))
    ins.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ins.xaxis.set_minor_formatter(NullFormatter())
    ins.set_xlabel(r"$E$", fontsize=8, labelpad=1)
    ins.set_ylabel(r"density in $\log_{10}E$", fontsize=7)
    ins.tick_params(labelsize=7)
    ins.legend(fontsize=6, loc="upper left", frameon=False)


def _mu_panel(bx, tab, numbers, t_right):
    """Panel (b): local μ on sliding windows, μ = 1, the paper's μ and the fitted μ of every convention."""
    w_lo, w_hi = numbers["fit_window"]
    s = tab[tab["kind"] == "sliding"]
    bx.errorbar(
        s["t_mid"],
        s["mu_free"],
        yerr=3 * s["mu_free_err"],
        fmt="o-",
        ms=3,
        lw=1,
        color="#0b2f6b",
        capsize=2,
        label=r"local $\mu$ (slope of $\log\langle E\rangle$), $\pm3\sigma$",
    )
    bx.axhline(1.0, color="k", lw=0.9, ls="-", label=r"$\mu=1$ (linearised)")
    bx.hlines(
        numbers["paper_mu"],
        w_lo,
        w_hi,
        color="#d62728",
        lw=1.4,
        ls="--",
        label=f"paper: {numbers['paper_mu']:g} on [{w_lo:g}, {w_hi:g}]",
    )
    # fitted μ of each convention, drawn over the times its fit used (the E > E_c curve ends early)
    styles = {
        ("inside", True): ("#ff7f0e", "-"),
        ("inside", False): ("#9467bd", "-"),
        ("above", True): ("#2ca02c", "-."),
        ("above", False): ("#2ca02c", "-."),
    }
    drawn = set()
    for r in numbers["authors_convention"]["mu"]:
        lo, hi = r["window"][0], r["t_last"]
        if (r["selection"], lo, hi) in drawn:  # the E > E_c fits coincide once its curve has ended
            continue
        drawn.add((r["selection"], lo, hi))
        color, ls = styles[(r["selection"], r["window"] == [w_lo, w_hi])]
        who = {(True, True): "ours = authors': ", (True, False): "ours: ", (False, True): "authors': "}.get(
            (r["ours"], r["authors"]), ""
        )
        sel = r"$E>E_c$ only" if r["selection"] == "above" else "all inside"
        bx.hlines(
            r["value"],
            lo,
            hi,
            color=color,
            lw=1.8,
            ls=ls,
            label=f"{who}{sel}, {format_value_err(r['value'], r['err'])} on [{lo:g}, {hi:g}]",
        )
    bx.set_xlim(-0.01 * t_right, t_right)
    bx.set_xlabel(r"$t$")
    bx.set_ylabel(r"$\mu$")
    # below the panel: inside it the legend would hide the short segments near μ ≈ 0.87–0.92
    bx.legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2, frameon=False)
    bx.grid(True, alpha=0.3)
