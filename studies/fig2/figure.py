"""Fig. 2 of the paper: P(t) at two energies (a) and κ0(E) (b). Draws only."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot
from hhscatter.publish.formatting import format_value_err

PT_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple")


def _fmt_err(v, e):
    """'0.061 ± 0.014': hhscatter.publish.formatting.format_value_err (the report's and the docs' rounding)."""
    return format_value_err(v, e)


def _sci(n):
    """LaTeX 'a×10^b' for an integer count (plain digits below 10^4)."""
    if n < 10_000:
        return f"{n:d}"
    b = int(np.floor(np.log10(n)))
    a = n / 10**b
    return (f"{a:.3g}" + r"\times" if abs(a - 1) > 1e-9 else "") + f"10^{{{b}}}"


def _paper_law_label(pp):
    """Legend text of the paper's κ(E) law from fig2.json's "paper" constants."""
    return f"paper: ${pp['a']:g}x^2 + {pp['b']:g}x$; ${pp['c']:g}x$"


def _panel_a(ax, curves, lines, numbers):
    pt = numbers["Pt"]
    t_right = 0.0
    inset = None
    for i, (key, info) in enumerate(sorted(pt.items())):
        E = float(key.split("_E")[1])
        colour = PT_COLOURS[i % len(PT_COLOURS)]
        c = curves[np.isclose(curves["energy"], E)]
        keep = c["P"].to_numpy() > 0
        t, P, err = c["t"].to_numpy()[keep], c["P"].to_numpy()[keep], c["P_err"].to_numpy()[keep]
        kap = info["kappa"]
        ax.plot(
            t,
            P,
            color=colour,
            lw=1.5,
            label=rf"$E_0 = {E:.2f}$ ($N = {_sci(info['n'])}$): $\kappa = {_fmt_err(kap['value'], kap['err'])}$",
        )
        ax.fill_between(t, np.clip(P - err, P * 0.05, None), P + err, color=colour, alpha=0.25, lw=0)
        ln = lines[np.isclose(lines["energy"], E)]
        ex = ln[ln["kind"] == "exponential"]
        ax.plot(ex["t"], ex["P"], "--", color="k", lw=1.0)
        t_right = max(t_right, 1.6 * float(info.get("tail_window", [0, info["t_floor"]])[1]), 1.3 * info["t_stop"])
        if info.get("tail_detected"):
            Pe = c["P_esc"].to_numpy()
            ke = Pe > 0
            ax.plot(
                c["t"].to_numpy()[ke],
                Pe[ke],
                color=colour,
                lw=0.9,
                ls=(0, (4, 2)),
                label=rf"$E_0 = {E:.2f}$, escaping orbits only ($P_{{esc}}$)",
            )
            pl = ln[ln["kind"] == "power_law"]
            win = info["tail_window"]
            on = (pl["t"] >= 0.85 * win[0]) & (pl["t"] <= 1.15 * win[1])
            ax.plot(pl["t"][on], pl["P"][on], ":", color="k", lw=1.8)
            z = info["z"]
            ax.annotate(
                rf"$t^{{-z}},\ z = {_fmt_err(z['value'], z['err'])}$",
                (pl["t"][on].iloc[len(pl["t"][on]) // 2], pl["P"][on].iloc[len(pl["t"][on]) // 2]),
                xytext=(10, 4),
                textcoords="offset points",
                color=colour,
                fontsize=9,
            )
            ts = info["tau_star"] if info.get("tau_star") is not None else info["tau_c"]
            ax.axvline(ts, color=colour, lw=0.9, ls="-.", alpha=0.8)
            ax.annotate(
                rf"$\tau^\star \approx {ts:.0f}$",
                (ts, 0.3),
                xycoords=("data", "axes fraction"),
                xytext=(4, 0),
                textcoords="offset points",
                color=colour,
                fontsize=9,
                rotation=90,
            )
            # inset: log–log view of the escaping orbits' tail
            if inset is None:
                inset = ax.inset_axes([0.62, 0.50, 0.35, 0.36])
            ok = (Pe > 0) & (c["t"].to_numpy() > 1)
            inset.loglog(c["t"].to_numpy()[ok], Pe[ok], color=colour, lw=1.2)
            inset.loglog(c["t"].to_numpy()[ok], c["P"].to_numpy()[ok], color=colour, lw=0.8, ls="--", alpha=0.6)
            inset.loglog(pl["t"], pl["P"], ":", color="k", lw=1.4)
            inset.axvline(ts, color=colour, lw=0.8, ls="-.")
            lt = info.get("late_tail")
            if lt:
                zr = lt["z_mle_trapped_removed"]
                inset.text(
                    0.03,
                    0.04,
                    f"$t > {lt['t_window'][0]:.0f}$: {lt['n_events']} escapes,\n"
                    rf"$z_{{MLE}} = {_fmt_err(zr['value'], zr['err'])}$",
                    transform=inset.transAxes,
                    fontsize=7,
                    va="bottom",
                )
            inset.set_xlabel("$t$", fontsize=8, labelpad=1)
            inset.set_ylabel(r"$P_{esc}(t)$", fontsize=8, labelpad=1)
            inset.tick_params(labelsize=7)
            inset.set_title(
                f"$E_0={E:.2f}$: escaping orbits (solid), all (dashed;\n"
                f"censored fraction {info['trapped_fraction']:.1e})",
                fontsize=7,
            )
    ax.set_yscale("log")
    ax.set_xlim(0, t_right)
    ymin = min(float(np.nanmin(curves["P"][curves["P"] > 0])), 1e-3)
    ax.set_ylim(max(ymin * 0.5, 1e-8), 1.5)
    ax.set_xlabel("time $t$")
    ax.set_ylabel("survival probability $P(t)$")
    ax.legend(loc="lower left", fontsize=8.5)
    ax.set_title(
        r"(a) $P(t)$, Hamiltonian ($\gamma = 0$); dashed: $f_0 e^{-\kappa t}$, dotted: $f_{*}\, t^{-z}$",
        loc="left",
        fontsize=10,
    )
    ax.grid(True, which="major", alpha=0.3)


def _panel_b(ax, kappa_e, fit_curve, cm, numbers):
    fit = numbers["kappa_fit"]
    ax.errorbar(
        kappa_e["x"],
        kappa_e["kappa"],
        yerr=kappa_e["kappa_err"],
        fmt="o",
        ms=4,
        color="tab:blue",
        ecolor="tab:blue",
        capsize=2,
        label=r"$\kappa_0$ from $P(t)$: mean of 4 window fits (bar: spread $\oplus$ stat.)",
        zorder=4,
    )
    main = cm[cm["shift_efolds"] == 0.0]
    if len(main):
        ax.errorbar(
            main["x"],
            main["kappa_cm"],
            yerr=main["kappa_cm_err"],
            fmt="D",
            ms=6,
            mfc="none",
            mec="tab:red",
            ecolor="tab:red",
            capsize=2,
            zorder=5,
            label=r"$\kappa$ from the c-measure, $\int e^{\kappa T} d\mu_c = 1 + \mu_c(\mathcal{E})$",
        )
    styles = {"nonlinear": ("tab:green", "--"), "linear": ("tab:orange", "--")}
    for regime, (colour, ls) in styles.items():
        f = fit_curve[(fit_curve["model"] == "continuous") & (fit_curve["regime"] == regime)]
        if regime == "nonlinear":
            lab = (
                rf"$a x^2 + b x$: $a = {_fmt_err(fit['a']['value'], fit['a']['err'])}$, "
                rf"$b = {_fmt_err(fit['b']['value'], fit['b']['err'])}$"
            )
        else:
            lab = rf"$c x$: $c = {_fmt_err(fit['c']['value'], fit['c']['err'])}$"
        ax.plot(f["x"], f["kappa"], ls, color=colour, lw=1.6, label=lab)
        p = fit_curve[(fit_curve["model"] == "paper") & (fit_curve["regime"] == regime)]
        ax.plot(
            p["x"],
            p["kappa"],
            ":",
            color="0.45",
            lw=1.0,
            label=_paper_law_label(numbers["paper"]) if regime == "linear" else None,
        )
    xb = fit["E_b"]["value"] - numbers["E_c"]
    ax.axvline(
        xb,
        color="tab:purple",
        ls="-.",
        lw=1.2,
        label=rf"break $E_b = {_fmt_err(fit['E_b']['value'], fit['E_b']['err'])}$",
    )
    ax.set_xlabel(r"$E_0 - E_c$")
    ax.set_ylabel(r"escape rate $\kappa_0$ (1/time)")
    ax.set_xlim(0, None)
    ax.set_ylim(0, None)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(r"(b) $\kappa_0(E_0)$, $x = E_0 - E_c$, $E_c = 1/6$", loc="left", fontsize=10)
    ax.grid(True, alpha=0.3)


CONVENTION_STYLE = {  # marker, colour, offset in x (so that the 4 bars do not overlap)
    "disk_plateau": ("o", "tab:blue", -0.0015),
    "disk_plevel": ("s", "tab:cyan", -0.0005),
    "square_plateau": ("^", "tab:red", 0.0005),
    "square_plevel": ("v", "tab:orange", 0.0015),
}


def _panel_c(ax, conv_table, numbers):
    """κ0 near E_c under the 4 conventions; ill-defined points as crosses on the axis, unstable energies shaded."""
    conv = numbers["kappa_conventions"]
    x_max = 0.30 - numbers["E_c"]
    near = conv_table[conv_table["x"] <= x_max + 1e-9]
    for name, label in conv["conventions"].items():
        m, colour, dx = CONVENTION_STYLE[name]
        d = near[near["convention"] == name]
        ok = d[d["defined"]]
        ax.errorbar(
            ok["x"] + dx,
            ok["kappa"],
            yerr=ok["kappa_err"],
            fmt=m,
            ms=4.5,
            color=colour,
            capsize=2,
            mfc="none" if "plevel" in name else colour,
            label=label,
            zorder=4,
        )
        bad = d[~d["defined"]]
        if len(bad):
            ax.plot(bad["x"] + dx, np.zeros(len(bad)), "x", color=colour, ms=8, mew=2, clip_on=False, zorder=5)
    for e in conv["unstable_energies"]:
        x = e - numbers["E_c"]
        if x <= x_max:
            ax.axvspan(x - 0.003, x + 0.003, color="0.85", zorder=0)
    law = conv.get("law") or {}
    xs = np.linspace(0, x_max, 200)
    if law:
        a, b, c = law["a"]["value"], law["b"]["value"], law["c"]["value"]
        xb = law["E_b"]["value"] - numbers["E_c"]
        lo, hi = xs[xs <= xb], xs[xs >= xb]
        ax.plot(
            lo,
            a * lo**2 + b * lo,
            "-",
            color="k",
            lw=1.2,
            label=rf"law across conventions: $a = {_fmt_err(a, law['a']['err'])}$, "
            rf"$b = {_fmt_err(b, law['b']['err'])}$, $c = {_fmt_err(c, law['c']['err'])}$",
        )
        ax.plot(hi, c * hi, "-", color="k", lw=1.2)
    pp = numbers["paper"]  # the paper's law (Fig. 2b caption), as the study recorded it
    xp = pp["E_b"] - numbers["E_c"]
    ax.plot(
        xs[xs <= xp],
        pp["a"] * xs[xs <= xp] ** 2 + pp["b"] * xs[xs <= xp],
        ":",
        color="0.45",
        lw=1.0,
        label=_paper_law_label(pp),
    )
    ax.plot(xs[xs >= xp], pp["c"] * xs[xs >= xp], ":", color="0.45", lw=1.0)
    ax.plot([], [], "x", color="0.3", ms=7, mew=2, label="κ ill-defined (plateau of censored orbits): excluded")
    ax.fill_between([], [], color="0.85", label=f"unstable across conventions (> {conv['stable_rel_tol']:.0%})")
    ax.set_xlim(0, x_max + 0.006)
    ax.set_ylim(0, None)
    ax.set_xlabel(r"$E_0 - E_c$")
    ax.set_ylabel(r"$\kappa_0$ (1/time)")
    ax.legend(loc="upper left", fontsize=7.5)
    ax.set_title(
        r"(c) $\kappa_0$ near $E_c$: IC region (disk, authors' square) $\times$ windows "
        rf"(plateau, $P = {conv['p_levels'][0]:g} \to {conv['p_levels'][1]:g}$)",
        loc="left",
        fontsize=10,
    )
    ax.grid(True, alpha=0.3)


def plot_fig2(curves, lines, kappa_e, fit_curve, cm, numbers, path, conv_table=None):
    """plot_fig2(curves, lines, kappa_e, fit_curve, cm, numbers, path, conv_table=None) -> None; writes the PNG.

    Inputs are fig2's derived tables (survival_curves, pt_fit_lines,
    kappa_energy, kappa_fit_curve, kappa_cmeasure, kappa_conventions) and
    fig2.json. Panel (c), κ0 near E_c under the 4 conventions, is drawn when
    ``conv_table`` is given.
    """
    plt = agg_pyplot()
    rows = 3 if conv_table is not None else 2
    fig, axes = plt.subplots(rows, 1, figsize=(7.0, 5.0 * rows), constrained_layout=True)
    _panel_a(axes[0], curves, lines, numbers)
    _panel_b(axes[1], kappa_e, fit_curve, cm, numbers)
    if conv_table is not None:
        _panel_c(axes[2], conv_table, numbers)
    fig.savefig(path, dpi=180)
    plt.close(fig)
