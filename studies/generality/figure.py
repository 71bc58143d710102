"""Figure of study ``generality`` (draws the derived tables and generality.json; computes nothing but the laws'
curves from their fitted parameters)."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels

COLORS = {"henon_heiles": "#2166ac", "contopoulos": "#b2182b", "barbanis": "#1b7837"}
MARKERS = {"henon_heiles": "o", "contopoulos": "s", "barbanis": "^"}


def _label(name, sysinfo):
    return f"{name.replace('_', '–').title()} ({sysinfo['n_exits']} exits, $E_c$ = {sysinfo['E_c']:.4g})"


def _panel_kappa(ax, kappa, numbers):
    for name, info in numbers["systems"].items():
        col, mk = COLORS.get(name, "k"), MARKERS.get(name, "o")
        d = kappa[(kappa["system"] == name) & (kappa["convention"] == "plateau")]
        ok = d["defined"].astype(bool)
        ax.errorbar(
            d.loc[ok, "eps"],
            d.loc[ok, "kappa"],
            d.loc[ok, "kappa_err"],
            fmt=mk,
            color=col,
            ms=5,
            capsize=2,
            label=_label(name, info),
        )
        ax.plot(d.loc[~ok, "eps"], d.loc[~ok, "kappa"], "x", color=col, ms=7)  # plateau of censored orbits: ill-defined
        e = kappa[(kappa["system"] == name) & (kappa["convention"] == "escaping") & kappa["defined"]]
        ax.plot(e["eps"], e["kappa"], mk, mfc="none", color=col, ms=8, alpha=0.7)
        laws = info["kappa_law"]
        conv = "plateau" if laws.get("plateau") else "escaping"
        law = laws.get(conv)
        if law:
            a, b, c, eb = (law[k]["value"] for k in ("a", "b", "c", "eps_b"))
            x = np.geomspace(max(float(d["eps"].min()) / 1.3, 1e-3), float(d["eps"].max()) * 1.2, 200)
            ax.plot(
                x,
                np.where(x < eb, a * x * x + b * x, c * x),
                "-" if conv == "plateau" else "--",
                color=col,
                lw=1,
                alpha=0.8,
            )
            ax.axvline(eb, color=col, ls=":", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$\epsilon = (E - E_c)/E_c$")
    ax.set_ylabel(r"$\kappa_0$ (1/time; well frequency 1)")
    ax.set_title(
        "(a) κ0: filled all orbits, × ill-defined (plateau of censored orbits),\nopen escaping orbits only; "
        "lines: law aε²+bε | cε, dotted: break",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="lower right")


def _panel_mu_of_E(ax, mu, numbers):
    for name in numbers["systems"]:
        col = COLORS.get(name, "k")
        d = mu[mu["system"] == name]
        w = d[d["kind"] == "microcanonical well"].sort_values("ratio")
        ax.plot(w["ratio"], w["mu"], "-", color=col, lw=1)
        c = d[d["kind"] == "c-measure"]
        ax.errorbar(c["ratio"], c["mu"], c["mu_err"], fmt=MARKERS.get(name, "o"), color=col, ms=5, capsize=2)
        a = d[d["kind"] == "all survivors"]
        ax.plot(a["ratio"], a["mu"], MARKERS.get(name, "o"), mfc="none", color=col, ms=7, alpha=0.6)
    ax.axvline(1.0, color="0.5", lw=0.8, ls="--")
    ax.set_xlabel(r"$E/E_c$")
    ax.set_ylabel(r"$2\langle K\rangle/E$ of the conservative system")
    ax.set_title("(b) μ(E): line microcanonical well, filled c-measure, open all survivors", fontsize=9)


def _panel_mu(ax, numbers, paper_mu):
    lo, hi = 0.8, 1.1
    for name, info in numbers["systems"].items():
        for wname, bw in info["mu_by_window"].items():
            m, p = bw["measured"], bw["predicted_c_measure"]
            if m["value"] is None or p["value"] is None:
                continue
            w = bw["window"]
            ax.errorbar(
                p["value"],
                m["value"],
                xerr=p["err"],
                yerr=m["err"],
                fmt=MARKERS.get(name, "o"),
                color=COLORS.get(name, "k"),
                ms=6,
                capsize=3,
                mfc=None if wname == "paper" else "none",
                label=f"{name}, t ∈ [{w[0]:g}, {w[1]:g}]",
            )
            lo, hi = min(lo, m["value"] - 0.03, p["value"] - 0.03), max(hi, m["value"] + 0.03, p["value"] + 0.03)
    ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
    ax.axhline(paper_mu, color="0.5", ls=":", lw=0.8)
    ax.text(lo + 0.005, paper_mu + 0.004, "paper HH μ = 0.91", fontsize=7, color="0.4")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    ax.set_xlabel("μ predicted (conservative ⟨K⟩)")
    ax.set_ylabel("μ measured (⟨E⟩(t) fit)")
    ax.set_title(
        "(c) μ measured vs predicted (c-measure above E_c, microcanonical well below)\n"
        "filled: fig3's window [0, 200]; open: ⟨E⟩ > E_c window",
        fontsize=9,
    )
    ax.legend(fontsize=7)


def _panel_curves(ax, curves, numbers, gamma):
    for name in numbers["systems"]:
        col = COLORS.get(name, "k")
        d = curves[(curves["system"] == name) & (curves["t"] > 0)]
        for kind, ls in (("measured", "-"), ("predicted", "--")):
            k = d[d["kind"] == kind]
            ax.plot(
                k["t"],
                -np.log(k["mean_E_over_E0"]) / (gamma * k["t"]),
                ls,
                color=col,
                lw=1.4 if ls == "-" else 1,
                label=f"{name} {kind}",
            )
    ax.set_xlabel("t")
    ax.set_ylabel(r"$-\ln(\langle E\rangle/E_0)/(\gamma t)$")
    ax.set_title(f"(d) running μ of ⟨E⟩(t), γ = {gamma:g}: measured (solid), predicted path (dashed)", fontsize=9)
    ax.legend(fontsize=6, ncol=2)


def _panel_kappa_cm(ax, numbers):
    """(e) claim 2: κ from the c-measure against κ0 of P(t) at the same E/E_c (escaping orbits; filled where the
    paper's all-orbit κ0 is defined too)."""
    lo, hi = np.inf, 0.0
    for name, info in numbers["systems"].items():
        col, mk = COLORS.get(name, "k"), MARKERS.get(name, "o")
        for r in info.get("kappa_cmeasure", []):
            if r["kappa_cm"] is None or r["kappa_escaping"] is None:
                continue
            filled = r["kappa_plateau"] is not None and r.get("ratio_minus_1_plateau") is not None
            ax.errorbar(
                r["kappa_escaping"],
                r["kappa_cm"],
                xerr=r["kappa_escaping_err"],
                yerr=r["kappa_cm_err"],
                fmt=mk,
                color=col,
                mfc=None if filled else "none",
                ms=6,
                capsize=2,
            )
            ax.annotate(
                f"{r['ratio']:g}",
                (r["kappa_escaping"], r["kappa_cm"]),
                fontsize=6,
                color=col,
                xytext=(4, -8),
                textcoords="offset points",
            )
            lo, hi = min(lo, r["kappa_escaping"], r["kappa_cm"]), max(hi, r["kappa_escaping"], r["kappa_cm"])
        ax.plot([], [], mk, color=col, label=name)
    if hi > 0:
        ax.plot([lo / 1.5, hi * 1.5], [lo / 1.5, hi * 1.5], "k-", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$\kappa_0$ from P(t) (escaping orbits, claim-1 run)")
    ax.set_ylabel(r"$\kappa$ from the c-measure, $\int e^{\kappa T} d\mu_c = 1 + \mu_c(\mathcal{E})$")
    ax.set_title(
        "(e) claim 2: κ from the c-measure vs κ0 (labels E/E_c);\nfilled: the paper's all-orbit κ0 defined "
        "too, open: ill-defined (plateau of censored orbits)",
        fontsize=9,
    )
    ax.legend(fontsize=7)


def _panel_distance(ax, numbers):
    """(f) claim 5: the survivors' distance to μ_c^{E(t*)} against that to μ_c^{E0} (paired intervals)."""
    top, text = 0.05, []
    for name, info in numbers["systems"].items():
        col, mk = COLORS.get(name, "k"), MARKERS.get(name, "o")
        c5 = info.get("cmeasure_distance") or {}
        for kind, filled in (("c-measure", True), ("all", False)):
            r = c5.get(kind) or {}
            if "d_star" not in r:
                if kind == "c-measure":
                    text.append(f"{name}: undetermined")
                continue
            if kind == "c-measure":
                dl = r["delta"]
                text.append(f"{name}: Δ = {dl['value']:+.2f} [{dl['interval'][0]:+.2f}, {dl['interval'][1]:+.2f}]")
            x, y = r["d_E0"], r["d_star"]
            ax.errorbar(
                x["value"],
                y["value"],
                xerr=[[x["value"] - x["interval"][0]], [x["interval"][1] - x["value"]]],
                yerr=[[y["value"] - y["interval"][0]], [y["interval"][1] - y["value"]]],
                fmt=mk,
                color=col,
                mfc=None if filled else "none",
                ms=6,
                capsize=2,
                label=f"{name}, {'μ_c (censored dropped)' if filled else 'all survivors'}",
            )
            top = max(top, x["interval"][1], y["interval"][1])
    ax.plot([0, top * 1.1], [0, top * 1.1], "k-", lw=0.8)
    ax.text(
        0.03,
        0.80,
        "paired Δ = d(μ_c^E0) − d(μ_c^E(t*)), μ_c:\n" + "\n".join(text),
        transform=ax.transAxes,
        ha="left",
        va="top",
        fontsize=7,
        bbox={"fc": "white", "ec": "0.8"},
    )
    ax.set_xlim(0, top * 1.1)
    ax.set_ylim(0, top * 1.1)
    ax.set_xlabel(r"d(survivors at t*, $\mu_c^{E_0}$)")
    ax.set_ylabel(r"d(survivors at t*, $\mu_c^{E(t^*)}$)")
    ax.set_title(
        "(f) claim 5, Fig. 5's test: debiased Hellinger distances (95 % paired intervals);\n"
        "below the diagonal: closer to the c-measure at E(t*)",
        fontsize=9,
    )
    ax.legend(fontsize=6)


def plot_generality(kappa, mu, curves, numbers, path):
    """plot_generality(κ table, μ table, ⟨E⟩ curves, numbers, path) -> None: the 6-panel figure as PNG."""
    plt = agg_pyplot()
    fig, axs = plt.subplots(3, 2, figsize=(11, 12.5))
    _panel_kappa(axs[0, 0], kappa, numbers)
    _panel_mu_of_E(axs[0, 1], mu, numbers)
    _panel_mu(axs[1, 0], numbers, numbers["config"]["study"].get("paper_mu", 0.91))
    _panel_curves(axs[1, 1], curves, numbers, numbers["config"]["study"]["mu_gamma"])
    _panel_kappa_cm(axs[2, 0], numbers)
    _panel_distance(axs[2, 1], numbers)
    fig.suptitle(
        f"generality ({numbers['scale']} scale): the paper's claims on three systems at the same E/E_c", fontsize=10
    )
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    save_panels(fig, path, dpi=150)  # each panel legible at a page's full width
    plt.close(fig)


# ---------------------------------------------------------------------------
# the evidence: regular fraction, Poincaré sections, long-time decay (one figure each, legible at full width)
# ---------------------------------------------------------------------------
KIND_COLORS = {"regular": "#2166ac", "chaotic": "#d6604d", "none": "#999999", "escaped": "#bbbbbb"}


def _name(label):
    return {"henon_heiles": "Hénon–Heiles"}.get(label, label.replace("_", "–").title())


def plot_regular(numbers, path):
    """Regular fraction against E/E_c per system and IC convention (shadow indicator); a count of 0 with its
    one-sided 95 % upper bound as the bar above it."""
    import pandas as pd

    plt = agg_pyplot()
    d = pd.DataFrame(numbers["regular_fraction"])
    fig, ax = plt.subplots(figsize=(8, 4.8))
    if "fraction_upper" not in d:
        d["fraction_upper"] = np.nan
    err = pd.to_numeric(d["err"], errors="coerce")
    # a count of 0: no error, its one-sided 95 % upper bound drawn as the bar above 0
    d = d.assign(lo=err.fillna(0.0), hi=err.fillna(pd.to_numeric(d["fraction_upper"], errors="coerce")).fillna(0.0))
    for (label, ics), g in d.groupby(["label", "ics"], sort=False):
        disk = "disk" in ics
        ax.errorbar(
            g["e_ratio"],
            g["fraction"],
            [g["lo"].to_numpy(), g["hi"].to_numpy()],
            fmt=("-" if disk else "--") + MARKERS.get(label, "o"),
            color=COLORS.get(label, "k"),
            mfc=None if disk else "none",
            ms=6,
            capsize=2,
            lw=1.2,
            label=f"{_name(label)}, {ics}",
        )
    ax.axhline(0.01, color="k", lw=0.8, ls=":")
    ax.text(d["e_ratio"].max(), 0.012, "1 %", ha="right", va="bottom", fontsize=9)
    ax.set_yscale("symlog", linthresh=0.01)
    ax.set_ylim(-0.001, 1.05)
    ax.set_xlabel(r"$E/E_c$")
    ax.set_ylabel("regular fraction of all orbits\n(bars: 1σ; at 0: 95 % upper bound)")
    r = d.iloc[0]
    ax.set_title(
        f"Regular orbits (shadow FTLE: separation growth < {r['g_max']:.0e} at t ≥ {r['t_from']:g}; "
        f"N = {int(r['n'])} per point)",
        fontsize=10,
    )
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def plot_sections(points, path):
    """Poincaré sections (x, y of the crossings ṙ = 0, φ̇ > 0) per system and energy, regular vs chaotic orbits."""
    plt = agg_pyplot()
    labels = list(dict.fromkeys(points["system"]))
    ratios = sorted(points["e_ratio"].unique())
    fig, axs = plt.subplots(len(ratios), len(labels), figsize=(4.3 * len(labels), 4.3 * len(ratios)), squeeze=False)
    for i, r in enumerate(ratios):
        for j, label in enumerate(labels):
            ax = axs[i, j]
            d = points[(points["system"] == label) & (points["e_ratio"] == r)]
            for kind in ("escaped", "none", "chaotic", "regular"):
                k = d[d["kind"] == kind]
                n = k["traj_id"].nunique()
                ax.plot(
                    k["x"],
                    k["y"],
                    ".",
                    ms=1.2,
                    mew=0,
                    color=KIND_COLORS[kind],
                    alpha=0.6 if kind != "regular" else 1,
                    label=f"{kind} ({n} orbits)" if n else None,
                    rasterized=True,
                )
            ax.set_aspect("equal")
            ax.set_title(f"{_name(label)}, E = {r:g} E_c", fontsize=10)
            ax.set_xlabel("x")
            ax.set_ylabel("y")
            leg = ax.legend(fontsize=7, loc="upper right", markerscale=20)
            for h in leg.legend_handles:
                h.set_alpha(1)
    fig.suptitle("Section crossings (ṙ = 0, φ̇ > 0) coloured by the shadow indicator of their orbit", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    save_panels(fig, path, dpi=200)  # each section at a page's full width (≈ 900 px), its legend legible
    plt.close(fig)


def plot_decay(curves, numbers, path):
    """P(t) to t_max of all orbits (solid) and of the non-regular orbits (dashed), and the plateau-plus-exponential
    fit (dotted), per system at three energies."""
    import pandas as pd

    plt = agg_pyplot()
    fits = pd.DataFrame(numbers["long_time"])
    labels = list(dict.fromkeys(curves["label"]))
    ratios = sorted(curves["e_ratio"].unique())
    show = [r for r in (1.05, 1.2, 1.5, 1.9) if r in ratios] or ratios[:3]
    fig, axs = plt.subplots(1, len(labels), figsize=(4.6 * len(labels), 4.6), squeeze=False, sharey=True)
    cmap = plt.get_cmap("viridis")
    for j, label in enumerate(labels):
        ax = axs[0, j]
        for k, r in enumerate(show):
            col = cmap(k / max(len(show) - 1, 1))
            d = curves[(curves["label"] == label) & (curves["e_ratio"] == r) & (curves["ics"] == "disk")]
            for what, ls in (("all", "-"), ("non-regular", "--")):
                c = d[(d["orbits"] == what) & (d["P"] > 0)]
                ax.plot(c["t"], c["P"], ls, color=col, lw=1.3, label=f"E = {r:g} E_c" if what == "all" else None)
            f = fits[(fits["label"] == label) & (fits["e_ratio"] == r) & fits["ics"].str.contains("disk")]
            if len(f) and f["P_inf"].notna().iloc[0]:
                f = f.iloc[0]
                t = np.linspace(f["t0"], d["t"].max(), 100)
                ax.plot(
                    t,
                    f["P_inf"] + (f["P_t0"] - f["P_inf"]) * np.exp(-f["kappa_inf"] * (t - f["t0"])),
                    ":",
                    color="k",
                    lw=1,
                )
        ax.set_yscale("log")
        ax.set_ylim(1e-4, 1.05)
        ax.set_xlabel("t")
        ax.set_title(_name(label), fontsize=10)
        if j == 0:
            ax.set_ylabel("P(t) (disk ICs, γ = 0)")
        ax.legend(fontsize=8, loc="lower left")
    fig.suptitle(
        "Long-time escape: all orbits (solid), non-regular orbits (dashed), plateau + exponential fit (dotted)",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    save_panels(fig, path, dpi=150)  # each panel legible at a page's full width
    plt.close(fig)
