"""Figure of the noise study (draws the derived tables and noise.json; computes nothing)."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels
from hhscatter.publish.readings import TURNOVER_TOLERANCE

COLORS = ("#1b7837", "#2166ac", "#b2182b", "#762a83", "#e08214")


def _panel_arrhenius(ax, k, fb=None):
    """(a) rate against ΔE/T at one γ: measured and Kramers–Langer (log scale), ratio in an inset with, where the
    numbers carry it, the fitted first correction a + c T/ΔE and its transition-state part 1 + c_TST T/ΔE."""
    ax.errorbar(k.barrier_over_T, k.rate, k.rate_err, fmt="o", color=COLORS[1], ms=4, capsize=2, label="measured")
    b = np.linspace(k.barrier_over_T.min() - 0.3, k.barrier_over_T.max() + 0.3, 50)
    # Kramers–Langer ∝ e^{−ΔE/T}: its prefactor from the records (the same at every T for fixed γ)
    pref = float((k.kramers_langer * np.exp(k.barrier_over_T)).iloc[0])
    ax.plot(b, pref * np.exp(-b), "-", color="k", lw=1, label="Kramers–Langer")
    ax.set_yscale("log")
    ax.set_xlabel(r"barrier $\Delta E/T$")
    ax.set_ylabel(r"escape rate $k$")
    ax.set_title(rf"(a) heat bath, $\gamma$ = {k.gamma.iloc[0]:g}", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")
    ins = ax.inset_axes([0.58, 0.62, 0.38, 0.33])
    ins.errorbar(k.barrier_over_T, k.ratio, k.ratio_err, fmt="o", color=COLORS[1], ms=3, capsize=2)
    ins.axhline(1.0, color="k", lw=0.8)
    if fb is not None:
        a, c, c_tst = fb["intercept"]["value"], fb["slope"]["value"], fb["transition_state_slope"]
        ins.plot(b, a + c / b, "-", color=COLORS[1], lw=0.9, label="fit")
        ins.plot(b, 1 + c_tst / b, "--", color="0.4", lw=0.9, label=r"$1 + c_{TST}\,T/\Delta E$")
        ins.legend(fontsize=5.5, loc="lower right")
    ins.set_ylabel(r"$k/k_{KL}$", fontsize=7)
    ins.tick_params(labelsize=7)


def _shell_curve(ax, t):
    """The energy-diffusion rate of the well's shells with the flux above E_b, where the records carry it."""
    if "shell_energy_diffusion" in t:
        ax.plot(t.gamma, t.shell_energy_diffusion, "--", color=COLORS[1], lw=1.1, label="energy diffusion, 2-D shells")


def _panel_turnover(ax, t):
    """(b) rate against γ at fixed T: measured, Kramers–Langer (the spatial-diffusion branch) and, where the
    records carry them, Mel'nikov–Meshkov and the energy-diffusion limit."""
    t = t.sort_values("gamma")
    ax.errorbar(t.gamma, t.rate, t.rate_err, fmt="o", color=COLORS[2], ms=4, capsize=2, label="measured")
    ax.plot(t.gamma, t.kramers_langer, "-", color="k", lw=1, label="Kramers–Langer")
    if "melnikov_meshkov" in t:  # the turnover theory at the measured γ and its energy-diffusion limit
        ax.plot(t.gamma, t.melnikov_meshkov, "-", color=COLORS[3], lw=1.2, label=r"Mel'nikov–Meshkov $\Upsilon k_{KL}$")
        ax.plot(t.gamma, t.energy_diffusion, ":", color="0.4", lw=1, label=r"energy diffusion $\delta k_{TST}$")
        _shell_curve(ax, t)
        ax.set_ylim(0.5 * float(t.rate.min()), 2 * float(t.kramers_langer.max()))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"drag $\gamma$")
    ax.set_ylabel(r"escape rate $k$")
    ax.set_title(rf"(b) turnover, $\Delta E/T$ = {t.barrier_over_T.iloc[0]:.3g}", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")


def _panel_reactivation(ax, r, num):
    """(c) the paper's P(t) with drag, without and with temperature, and the re-activation extension."""
    ax.plot(r.t, r.P_0, "-", color="0.5", lw=1.2, label="T = 0: $P(t)$ (settled leave)")
    ax.plot(r.t, r.P_0_settled_inside, "--", color="0.5", lw=1, label="T = 0: settled counted inside")
    ax.plot(r.t, r.P_T, "-", color=COLORS[0], lw=1.5, label=f"T = {num['temperature']:.3g}")
    ax.plot(r.t, r.model, ":", color="k", lw=1.5, label="re-activation at the thermal rate")
    ax.set_yscale("log")
    ax.set_ylim(max(1e-3, float(np.nanmin(r.P_T[r.P_T > 0])) / 2), 1.05)
    ax.set_xlabel("t")
    ax.set_ylabel("P(t)")
    ax.set_title(rf"(c) $E_0$ = {num['energy']:g}, $\gamma$ = {num['gamma']:g}", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")


def _panel_no_drag(ax, nd):
    """(d) P(t) without drag for each noise strength σ (σ = 0: the conservative κ0)."""
    styles = ("-", "--")
    for i, (E, g) in enumerate(nd.groupby("energy")):
        for j, (s, h) in enumerate(g.groupby("sigma")):
            lab = f"E = {E:.2f}, σ = {s:g}"
            ax.plot(h.t, h.P, styles[i % 2], color=COLORS[j % len(COLORS)], lw=1.2, label=lab)
    ax.set_yscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel("P(t)")
    ax.set_title(r"(d) noise without drag", fontsize=10)
    ax.legend(fontsize=6.5, loc="upper right", ncol=2)


def _panel_survivors(ax, survivors, e_c):
    """(e) the mean energy of the orbits still inside against t at the largest σ, each E0: against E0 + σ²t (the
    whole ensemble's mean) and E_c."""
    rows = [r for r in survivors if r.get("mean_energy") is not None]
    s_max = max(r["sigma"] for r in survivors)
    for i, E in enumerate(sorted({r["energy"] for r in survivors})):
        c = COLORS[(i + 1) % len(COLORS)]
        rs = sorted((r for r in rows if r["energy"] == E and r["sigma"] == s_max), key=lambda r: r["t"])
        ax.errorbar(
            [r["t"] for r in rs],
            [r["mean_energy"] for r in rs],
            [r["mean_energy_err"] for r in rs],
            fmt="o-",
            color=c,
            ms=4,
            lw=1,
            capsize=2,
            label=f"$E_0$ = {E:.2f}: orbits inside",
        )
        all_t = sorted({r["t"] for r in survivors})
        ax.plot(
            [0.0, *all_t],
            [E + s_max**2 * t for t in (0.0, *all_t)],
            ":",
            color=c,
            lw=1,
            label=rf"$E_0 + \sigma^2 t$, $E_0$ = {E:.2f} (all orbits)",
        )
    if e_c is not None:
        ax.axhline(e_c, color="k", lw=0.8, ls="--", label=r"$E_c$")
    ax.set_xlabel("t")
    ax.set_ylabel(r"mean energy $\langle E\rangle$")
    ax.set_title(rf"(e) without drag, $\sigma$ = {s_max:g}: the orbits still inside", fontsize=10)
    ax.legend(fontsize=6.5, loc="center right")


def _panel_two_saddles(ax, d):
    """(f) the two-saddle system: rate against ΔE/T, measured, the multi-saddle Kramers–Langer sum and its lowest
    saddle's term alone."""
    recs = sorted(d["records"], key=lambda r: r["barrier_over_T"])
    b = np.array([r["barrier_over_T"] for r in recs])
    ax.errorbar(
        b,
        [r["rate"] for r in recs],
        [r["rate_err"] for r in recs],
        fmt="o",
        color=COLORS[4],
        ms=4,
        capsize=2,
        label="measured",
    )
    ax.plot(b, [r["kramers_langer"] for r in recs], "s-", color="k", ms=3, lw=1, label=r"$\sum_s k_{KL,s}$")
    ax.plot(b, [r["kramers_langer_lowest"] for r in recs], "^--", color="0.5", ms=3, lw=1, label="lowest saddle only")
    ax.set_yscale("log")
    ax.set_xlabel(r"$\Delta E/T$ (lowest saddle)")
    ax.set_ylabel(r"escape rate $k$")
    ax.set_title(f"(f) two saddles: V = {d['potential_text']}", fontsize=9)
    ax.legend(fontsize=7, loc="lower left")


def _panel_theory_ratios(ax, series, tol):
    """(g) the rate over the Mel'nikov–Meshkov/PGH rate against γ for each turnover series, the band 1 ± ``tol`` and
    the theory's range (γ/ω_b up to its stated bound)."""
    for (label, t), color, marker in zip(series, COLORS[2:], "osD"):
        t = t.sort_values("gamma")
        ax.errorbar(t.gamma, t.ratio_mm, 2 * t.ratio_mm_err, fmt=marker + "-", color=color, ms=4, capsize=2, lw=0.8,
                    label=label)  # fmt: skip
        inside = t[t.theory_assumptions_hold.astype(bool)]
        if len(inside) and len(inside) < len(t):  # from half way (in log γ) past the range's last point
            edge = np.sqrt(float(inside.gamma.max()) * float(t.gamma[t.gamma > inside.gamma.max()].min()))
            ax.axvspan(edge, float(t.gamma.max()) * 1.5, color="0.93", zorder=0)
    ax.axhspan(1 - tol, 1 + tol, color=COLORS[0], alpha=0.12, lw=0, label=rf"$1 \pm {tol:g}$")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel(r"drag $\gamma$ (shaded: beyond the theory's range)")
    ax.set_ylabel(r"$k / \Upsilon(\delta) k_{KL}$  (bars: 2σ)")
    ax.set_title("(g) the turnover against Mel'nikov–Meshkov/PGH", fontsize=10)
    ax.legend(fontsize=7, loc="upper right")


def _panel_saddles_turnover(ax, t, barrier):
    """(h) the two-saddle system's rate against γ: measured, the Kramers–Langer sum, the Mel'nikov–Meshkov/PGH sum
    and the energy-diffusion limit."""
    t = t.sort_values("gamma")
    ax.errorbar(t.gamma, t.rate, t.rate_err, fmt="o", color=COLORS[4], ms=4, capsize=2, label="measured")
    ax.plot(t.gamma, t.kramers_langer, "-", color="k", lw=1, label=r"$\sum_s k_{KL,s}$")
    ax.plot(t.gamma, t.melnikov_meshkov, "-", color=COLORS[3], lw=1.2, label=r"$\sum_s \Upsilon(\delta_s) k_{KL,s}$")
    ax.plot(t.gamma, t.energy_diffusion, ":", color="0.4", lw=1, label=r"$\sum_s \delta_s k_{TST,s}$")
    _shell_curve(ax, t)
    ax.set_ylim(0.5 * float(t.rate.min()), 2 * float(t.kramers_langer.max()))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"drag $\gamma$")
    ax.set_ylabel(r"escape rate $k$")
    ax.set_title(rf"(h) two saddles: turnover, $\Delta E/T$ = {barrier:.3g} (lowest saddle)", fontsize=10)
    ax.legend(fontsize=7, loc="lower right")


def plot_noise(*, rates, reactivation, no_drag, numbers, path, scale):
    """plot_noise(...) -> None: the study's panels in ``path``: four, and (e) the survivors' energies, (f) the
    two-saddle system, (g) the turnover series against the theory and (h) the two-saddle turnover where the numbers
    carry them."""
    plt = agg_pyplot()
    extra = (numbers.get("no_drag_survivors"), (numbers.get("two_saddles") or {}).get("records"))
    cols = 3 if any(extra) else 2
    high = rates[rates.set == "turnover_high"] if "set" in rates else rates.iloc[:0]
    saddles = rates[rates.set == "saddles_turnover"] if "set" in rates else rates.iloc[:0]
    rows = 3 if len(high) or len(saddles) else 2
    fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, 4 * rows), squeeze=False)
    _panel_arrhenius(
        axes[0, 0], rates[rates.set == "kramers"].sort_values("barrier_over_T"), numbers.get("finite_barrier")
    )
    _panel_turnover(axes[0, 1], rates[rates.set == "turnover"])
    _panel_reactivation(axes[1, 0], reactivation, numbers["reactivation"])
    _panel_no_drag(axes[1, 1], no_drag)
    if cols == 3:
        if numbers.get("no_drag_survivors"):
            _panel_survivors(axes[0, 2], numbers["no_drag_survivors"], numbers["conventions"].get("E_c"))
        else:
            axes[0, 2].set_visible(False)
        if (numbers.get("two_saddles") or {}).get("records"):
            _panel_two_saddles(axes[1, 2], numbers["two_saddles"])
        else:
            axes[1, 2].set_visible(False)
    if rows == 3:
        low = rates[rates.set == "turnover"]
        series = [(rf"ΔE/T = {t.barrier_over_T.iloc[0]:.3g}", t) for t in (low, high) if len(t)]
        if len(saddles):
            series.append((rf"two saddles, ΔE/T = {saddles.barrier_over_T.iloc[0]:.3g}", saddles))
        _panel_theory_ratios(axes[2, 0], series, TURNOVER_TOLERANCE)
        if len(saddles):
            _panel_saddles_turnover(axes[2, 1], saddles, (numbers.get("two_saddles_turnover") or {})["barrier_over_T"])
        else:
            axes[2, 1].set_visible(False)
        for ax in axes[2, 2:]:
            ax.set_visible(False)
    fig.suptitle(f"Hénon–Heiles in a heat bath and with noise ({scale} scale)", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    save_panels(fig, path, dpi=200)  # each panel legible at a page's full width (the inset travels with (a))
    plt.close(fig)
